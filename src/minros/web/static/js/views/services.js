// Services: call any service with a form generated from its .srv (rosapi's
// service_request_details), the response shown as a tree; a failing call shows the server's
// error next to the button.

import {errorLine, fill, h, messageForm, treeView} from "../ui.js";

export function createServicesView(app) {
  const filter = h("input", {type: "search", placeholder: "filter services", oninput: () => renderList()});
  const showDebug = h("input", {type: "checkbox", onchange: () => renderList()});
  const list = h("ul", {class: "service-list"});
  const panel = h("div", {class: "service-panel"}, h("p", {class: "muted"}, "Pick a service."));
  const el = h("section", {}, h("div", {class: "services-layout"},
    h("div", {}, h("div", {class: "toolbar"}, filter, h("label", {}, showDebug, " debug")), list), panel));
  let visible = false;
  let current = null;

  function renderList() {
    const text = filter.value.trim().toLowerCase();
    const services = app.graph.services.filter((s) => (showDebug.checked || !app.isQuiet(s.name) &&
      !s.name.endsWith("/get_loggers") && !s.name.endsWith("/set_logger_level")) && (!text || s.name.toLowerCase().includes(text)));
    fill(list, ...services.map((s) => h("li", {},
      h("a", {href: "javascript:void 0", class: s.name === current ? "active" : "", "data-service": s.name, onclick: () => pick(s.name)}, s.name),
      h("span", {class: "muted"}, " " + s.providers.join(", ")))));
  }

  async function pick(name) {
    current = name;
    renderList();
    fill(panel, h("h3", {}, h("code", {}, name)), h("p", {class: "muted"}, "reading its type…"));
    try {
      const {type} = await app.conn.rosapi("service_type", {service: name});
      if (!type) throw new Error(`cannot read the type of ${name}: is its server still running?`);
      const {typedefs} = await app.conn.rosapi("service_request_details", {type});
      if (current !== name) return;
      const form = messageForm(typedefs, typedefs.length ? typedefs[0].type : type + "Request");
      const error = errorLine();
      const response = treeView(3);
      const responseBox = h("div", {class: "response", hidden: true}, h("h4", {}, "Response"), response);
      const button = h("button", {class: "primary", onclick: async () => {
        let args;
        try {
          args = form.value();
        } catch (err) {
          error.show(err.message);
          return;
        }
        error.show("");
        button.disabled = true;
        try {
          const values = await app.conn.callService(name, args);
          responseBox.hidden = false;
          response.update(values);
          error.ok("called at " + new Date().toLocaleTimeString());
        } catch (err) {
          responseBox.hidden = true;
          error.show(err.message);
        } finally {
          button.disabled = false;
        }
      }}, "Call");
      fill(panel, h("h3", {}, h("code", {}, name), " ", h("span", {class: "muted"}, type)),
        form, h("div", {class: "toolbar"}, button), error, responseBox);
    } catch (err) {
      if (current === name) fill(panel, h("h3", {}, h("code", {}, name)), h("p", {class: "error"}, err.message));
    }
  }

  app.onGraph(() => { if (visible) renderList(); });

  return {
    id: "services", el,
    show() {
      visible = true;
      renderList();
    },
    hide() {
      visible = false;
    },
    open({service}) {
      if (service) pick(service);
    },
  };
}
