// Publish: any topic, the message filled from a form (generated from the type's definition)
// or typed as YAML (as `rostopic pub` reads it: {linear: {x: 2.0}}), once or at a rate until
// stopped. The server publishes (so a rate keeps going while the browser is busy) and says
// what is wrong with the YAML or a field next to the input.

import {clear, datalist, errorLine, fill, h, messageForm, yamlTemplate} from "../ui.js";

export function createPublishView(app) {
  const topic = h("input", {type: "text", placeholder: "/topic", list: "publish-topics", class: "topic-input",
    onchange: () => { const known = app.topicType(topic.value.trim()); if (known) { type.value = known; loadType(); } }});
  const type = h("input", {type: "text", placeholder: "pkg/Type", list: "publish-types", onchange: () => loadType()});
  const mode = h("select", {onchange: () => showMode()}, h("option", {value: "form"}, "form"), h("option", {value: "yaml"}, "YAML"));
  const rate = h("input", {type: "number", min: 0, max: 1000, step: "any", value: 0, class: "narrow", title: "0: publish once"});
  const formBox = h("div", {class: "publish-form"});
  const yaml = h("textarea", {rows: 8, class: "yaml-input", spellcheck: false, placeholder: "{linear: {x: 2.0}, angular: {z: 1.0}}"});
  const error = errorLine();
  const running = h("ul", {class: "running"});
  const el = h("section", {},
    h("div", {class: "toolbar"}, h("label", {}, "topic ", topic), h("label", {}, "type ", type), h("label", {}, "fill from ", mode)),
    formBox, yaml,
    h("div", {class: "toolbar"}, h("label", {}, "rate (Hz, 0 = once) ", rate), h("button", {class: "primary", onclick: () => start()}, "Publish")),
    error, h("h3", {}, "Publishing"), running);
  let form = null;
  let typedefs = [];
  const jobs = new Map();  // id -> {topic, rate, li}

  function showMode() {
    yaml.hidden = mode.value !== "yaml";
    formBox.hidden = mode.value !== "form";
  }

  async function loadType() {
    const name = type.value.trim();
    if (!name) return;
    try {
      const reply = await app.conn.rosapi("message_details", {type: name});
      typedefs = reply.typedefs;
      form = messageForm(typedefs, name);
      fill(formBox, form);
      if (!yaml.value.trim() || yaml.dataset.template === yaml.value) {
        yaml.value = yamlTemplate(typedefs, name);
        yaml.dataset.template = yaml.value;
      }
      error.show("");
    } catch (err) {
      form = null;
      clear(formBox);
      error.show(`${name}: ${err.message}`);
    }
  }

  async function start() {
    const fields = {topic: topic.value.trim(), type: type.value.trim(), rate: Number(rate.value) || 0};
    if (!fields.topic || !fields.type) {
      error.show("name the topic and its type");
      return;
    }
    if (mode.value === "yaml") {
      fields.yaml = yaml.value;
    } else {
      if (!form) await loadType();
      try {
        fields.msg = form ? form.value() : {};
      } catch (err) {
        error.show(err.message);
        return;
      }
    }
    const id = app.conn.newId("pub");
    try {
      const reply = await app.conn.request("pub_start", {id, ...fields});
      error.ok(reply.rate ? `publishing on ${reply.topic} at ${reply.rate} Hz` : `published once on ${reply.topic}`);
      if (reply.rate) addJob(id, reply.topic, reply.rate);
    } catch (err) {
      error.show(err.message);
    }
  }

  function addJob(id, name, hz) {
    const li = h("li", {}, h("code", {}, name), ` at ${hz} Hz `, h("button", {class: "small", onclick: () => {
      app.conn.send({op: "pub_stop", id});
      li.remove();
      jobs.delete(id);
    }}, "Stop"));
    jobs.set(id, {li});
    running.append(li);
  }

  app.onGraph((graph) => {
    datalist("publish-topics", graph.topics.map((t) => t.name));
    datalist("publish-types", [...new Set(graph.topics.map((t) => t.type).filter(Boolean))].sort());
  });
  app.conn.on("state", ({state}) => {
    if (state !== "connected") {  // the server stopped them with the session
      for (const job of jobs.values()) job.li.remove();
      jobs.clear();
    }
  });
  showMode();

  return {
    id: "publish", el,
    show() {},
    hide() {},
    open({topic: name, type: typeName}) {
      if (name) topic.value = name;
      if (typeName) {
        type.value = typeName;
        loadType();
      }
    },
  };
}
