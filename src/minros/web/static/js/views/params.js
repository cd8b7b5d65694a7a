// Parameters: the parameter server's tree, live (the master pushes changes), each value shown
// and edited as YAML (as rosparam set reads it: 1 is an int, 1.0 a double, [1, 2] a list);
// and the dynamic_reconfigure servers as forms (sliders for ranges, menus for enums).
// A string of several lines (a URDF on /robot_description, a launch file's text) is shown as
// text, folded under its first line and its size, and edited in a text box.

import {clear, errorLine, fill, h} from "../ui.js";

const DESCRIPTION_TYPE = "dynamic_reconfigure/ConfigDescription";

export function createParamsView(app) {
  const leaves = new Map();  // name -> {yaml, type}
  const open = new Set(["/"]);
  const openText = new Set();  // names of the multi-line strings shown unfolded
  const tree = h("div", {class: "param-tree"});
  const newName = h("input", {type: "text", placeholder: "/name", class: "param-name"});
  const newValue = h("input", {type: "text", placeholder: "value as YAML, e.g. 1.5 or [a, b]", class: "param-value",
    onkeydown: (e) => { if (e.key === "Enter") setNew(); }});
  const newError = errorLine();
  const filter = h("input", {type: "search", placeholder: "filter", oninput: () => render()});
  const dynList = h("div", {class: "dynrec-list"});
  const dynForm = h("div", {class: "dynrec-form"});
  const el = h("section", {},
    h("div", {class: "params-layout"},
      h("div", {},
        h("div", {class: "toolbar"}, filter),
        h("div", {class: "toolbar"}, newName, newValue, h("button", {onclick: () => setNew()}, "Set")), newError,
        tree),
      h("aside", {class: "dynrec"}, h("h3", {}, "dynamic_reconfigure"), dynList, dynForm)));
  let visible = false;
  let loaded = false;
  let dynServer = null;

  async function load() {
    try {
      const reply = await app.conn.request("params");
      leaves.clear();
      for (const [name, yaml, type] of reply.leaves) leaves.set(name, {yaml, type});
      loaded = true;
      render();
    } catch (err) {
      fill(tree, h("p", {class: "error"}, err.message));
    }
  }

  app.conn.on("param_changes", (msg) => {
    for (const name of msg.removed) leaves.delete(name);
    for (const [name, yaml, type] of msg.changed) leaves.set(name, {yaml, type});
    if (visible) render();
  });

  function build() {
    const text = filter.value.trim().toLowerCase();
    const root = {children: new Map()};
    for (const [name, leaf] of leaves) {
      if (text && !name.toLowerCase().includes(text)) continue;
      const parts = name.split("/").filter(Boolean);
      let node = root;
      parts.forEach((part, i) => {
        if (!node.children.has(part)) node.children.set(part, {children: new Map(), path: "/" + parts.slice(0, i + 1).join("/")});
        node = node.children.get(part);
      });
      node.leaf = {name, ...leaf};
    }
    return root;
  }

  function render() {
    const root = build();
    const forceOpen = Boolean(filter.value.trim());
    const renderChildren = (node) => h("ul", {}, [...node.children.entries()].sort(([a], [b]) => a.localeCompare(b)).map(([key, child]) => {
      if (child.leaf && !child.children.size) return h("li", {}, leafRow(key, child.leaf));
      const isOpen = forceOpen || open.has(child.path);
      const details = h("details", {open: isOpen, ontoggle: () => {
        if (details.open) open.add(child.path);
        else open.delete(child.path);
      }}, h("summary", {}, key + "/"), renderChildren(child));
      return h("li", {}, details);
    }));
    fill(tree, leaves.size || !loaded ? renderChildren(root) : h("p", {class: "muted"}, "No parameters."));
  }

  // the text of a multi-line string: the server sends it as a double-quoted scalar, which is
  // JSON (pagemodel.dumps_yaml); null for every other value
  function multiline(leaf) {
    if (leaf.type !== "string" || !leaf.yaml.startsWith('"')) return null;
    try {
      const text = JSON.parse(leaf.yaml);
      // a line ending in a newline ("noetic\n", as ROS sets /rosdistro) stays one line
      return typeof text === "string" && text.replace(/\n$/, "").includes("\n") ? text : null;
    } catch (err) {
      return null;
    }
  }

  function textRow(key, leaf, text) {
    const lines = text.split("\n");
    const count = text.endsWith("\n") ? lines.length - 1 : lines.length;
    const first = (lines.find((line) => line.trim()) || "").trim();
    const shown = first.length > 80 ? first.slice(0, 80) + "…" : first;
    const details = h("details", {class: "param-text", open: openText.has(leaf.name), ontoggle: () => {
      if (details.open) openText.add(leaf.name);
      else openText.delete(leaf.name);
    }},
      h("summary", {}, h("code", {}, shown), h("span", {class: "muted"}, ` ${count} lines, ${text.length} characters`)),
      h("pre", {class: "param-pre"}, text),
      h("button", {class: "small", onclick: () => edit()}, "Edit"));
    const row = h("div", {class: "param-row", "data-param": leaf.name},
      h("span", {class: "param-key"}, key), details, h("span", {class: "muted param-type"}, leaf.type),
      h("button", {class: "small", title: `delete ${leaf.name}`, onclick: () => remove(leaf.name)}, "×"));
    const edit = () => {
      const area = h("textarea", {class: "param-edit-text", rows: String(Math.min(24, count + 1)), spellcheck: "false"});
      area.value = text;
      const error = errorLine();
      const save = async () => {
        try {  // sent as a double-quoted scalar: the text exactly, whatever it holds
          await app.conn.request("param_set", {name: leaf.name, yaml: JSON.stringify(area.value)});
          openText.add(leaf.name);
        } catch (err) {
          error.show(err.message);
          area.focus();
        }
      };
      area.addEventListener("keydown", (e) => {
        if (e.key === "Enter" && (e.ctrlKey || e.metaKey)) save();
        if (e.key === "Escape") render();
      });
      details.replaceWith(h("span", {class: "param-editing"}, area,
        h("button", {class: "small", onclick: save, title: "Ctrl+Enter"}, "Save"),
        h("button", {class: "small", onclick: () => render(), title: "Escape"}, "Cancel"), error));
      area.focus();
    };
    return row;
  }

  function leafRow(key, leaf) {
    const text = multiline(leaf);
    if (text !== null) return textRow(key, leaf, text);
    const value = h("span", {class: "param-yaml", title: "click to edit", tabindex: "0"}, leaf.yaml);
    const row = h("div", {class: "param-row", "data-param": leaf.name},
      h("span", {class: "param-key"}, key), value, h("span", {class: "muted param-type"}, leaf.type),
      h("button", {class: "small", title: `delete ${leaf.name}`, onclick: () => remove(leaf.name)}, "×"));
    const edit = () => {
      const input = h("input", {type: "text", value: leaf.yaml, class: "param-edit"});
      const error = errorLine();
      const save = async () => {
        try {
          await app.conn.request("param_set", {name: leaf.name, yaml: input.value});
        } catch (err) {
          error.show(err.message);
          input.focus();
        }
      };
      input.addEventListener("keydown", (e) => {
        if (e.key === "Enter") save();
        if (e.key === "Escape") render();
      });
      value.replaceWith(h("span", {class: "param-editing"}, input, h("button", {class: "small", onclick: save}, "Save"), error));
      input.focus();
      input.select();
    };
    value.addEventListener("click", edit);
    value.addEventListener("keydown", (e) => { if (e.key === "Enter") edit(); });
    return row;
  }

  async function setNew() {
    const name = newName.value.trim();
    if (!name) {
      newError.show("type a parameter name, e.g. /my_node/gain");
      return;
    }
    try {
      await app.conn.request("param_set", {name, yaml: newValue.value});
      newError.show("");
      newValue.value = "";
      const parts = name.split("/").filter(Boolean);  // show where it went
      parts.forEach((_, i) => open.add("/" + parts.slice(0, i + 1).join("/")));
      render();
    } catch (err) {
      newError.show(err.message);
    }
  }

  async function remove(name) {
    try {
      await app.conn.request("param_delete", {name});
    } catch (err) {
      newError.show(err.message);
    }
  }

  // -- dynamic_reconfigure -------------------------------------------------------------

  function dynServers(graph) {
    return graph.topics.filter((t) => t.type === DESCRIPTION_TYPE && t.name.endsWith("/parameter_descriptions") && t.publishers.length)
      .map((t) => t.name.slice(0, -"/parameter_descriptions".length)).sort();
  }

  function renderDynList(graph) {
    const servers = dynServers(graph);
    fill(dynList, servers.length
      ? h("ul", {}, servers.map((s) => h("li", {}, h("a", {href: "javascript:void 0", class: s === dynServer ? "active" : "",
        onclick: () => openDyn(s)}, s))))
      : h("p", {class: "muted"}, "No dynamic_reconfigure servers."));
    if (dynServer && !servers.includes(dynServer)) {
      dynServer = null;
      clear(dynForm);
    }
  }

  async function openDyn(server) {
    dynServer = server;
    renderDynList(app.graph);
    fill(dynForm, h("p", {class: "muted"}, `reading ${server}…`));
    try {
      const reply = await app.conn.request("dynrec_get", {server});
      if (dynServer === server) fill(dynForm, h("h4", {}, server), dynGroup(server, reply.groups, reply.config));
    } catch (err) {
      if (dynServer === server) fill(dynForm, h("p", {class: "error"}, err.message));
    }
  }

  function dynGroup(server, group, config) {
    const box = h("fieldset", {class: "dyn-group"}, group.name && group.name !== "Default" ? h("legend", {}, group.name) : null);
    for (const param of group.parameters) box.append(dynParam(server, param, config));
    for (const sub of group.groups) box.append(dynGroup(server, sub, config));
    return box;
  }

  function dynParam(server, param, config) {
    const error = errorLine();
    const send = async (value) => {
      try {
        const reply = await app.conn.request("dynrec_set", {server, changes: {[param.name]: value}});
        error.show("");
        Object.assign(config, reply.config);
        show(reply.config[param.name]);
      } catch (err) {
        error.show(err.message);
      }
    };
    let control;
    let show;
    if (param.enum.length) {
      control = h("select", {onchange: () => send(param.type === "str" ? control.value : Number(control.value))},
        param.enum.map((c) => h("option", {value: c.value, title: c.description}, `${c.name} (${c.value})`)));
      show = (v) => { control.value = v; };
    } else if (param.type === "bool") {
      control = h("input", {type: "checkbox", onchange: () => send(control.checked)});
      show = (v) => { control.checked = Boolean(v); };
    } else if (param.type === "str") {
      control = h("input", {type: "text", onchange: () => send(control.value)});
      show = (v) => { control.value = v; };
    } else {
      const step = param.type === "int" ? 1 : (param.max - param.min) / 100 || "any";
      const slider = h("input", {type: "range", min: param.min, max: param.max, step});
      const number = h("input", {type: "number", class: "narrow", step: param.type === "int" ? 1 : "any"});
      slider.addEventListener("input", () => { number.value = slider.value; });
      slider.addEventListener("change", () => send(Number(slider.value)));
      number.addEventListener("change", () => send(Number(number.value)));
      control = h("span", {class: "pair"}, slider, number);
      show = (v) => { slider.value = v; number.value = v; };
    }
    show(config[param.name]);
    return h("div", {class: "field", "data-dynparam": param.name},
      h("label", {class: "field-label", title: param.description}, param.name,
        h("span", {class: "muted"}, ` ${param.type}` + (param.enum.length || param.type === "str" || param.type === "bool" ? "" : ` [${param.min}, ${param.max}]`))),
      control, error);
  }

  app.onGraph((graph) => { if (visible) renderDynList(graph); });
  app.conn.onOpen(() => { if (visible) load(); else loaded = false; });

  return {
    id: "params", el,
    show() {
      visible = true;
      if (!loaded) load();
      else render();
      renderDynList(app.graph);
    },
    hide() {
      visible = false;
    },
  };
}
