// About: what else this port serves (rosbridge, Foxglove, video), with this server's URLs.

import {h} from "../ui.js";
import {serverUrl} from "../conn.js";

export function createAboutView(app) {
  const scheme = location.protocol === "https:" ? "wss://" : "ws://";
  const ws = scheme + location.host + serverUrl("/");
  const node = h("code", {}, "…");
  const version = h("span", {});
  app.conn.onOpen(() => {
    node.textContent = app.conn.hello.node;
    version.textContent = app.conn.hello.version;
  });
  const el = h("section", {class: "about"},
    h("h3", {}, "minros web ", version),
    h("p", {}, "This page talks to the node ", node, " over one WebSocket. The same port serves:"),
    h("ul", {},
      h("li", {}, h("b", {}, "rosbridge v2"), " with ", h("b", {}, "rosapi"), ": connect roslibjs, roslibpy or webviz to ", h("code", {}, ws)),
      h("li", {}, "the ", h("b", {}, "Foxglove WebSocket"), " protocol: in Foxglove or Lichtblick open \"Foxglove WebSocket\" at the same URL"),
      h("li", {}, h("b", {}, "video"), ": ", h("a", {href: serverUrl("/streams")}, "image topics"), ", ",
        h("code", {}, "/stream?topic=..."), ", ", h("code", {}, "/snapshot?topic=..."), ", ", h("code", {}, "/stream_viewer?topic=..."))),
    h("p", {class: "muted"}, "Shift-click a menu entry to show two views side by side (or open #plot+images)."));
  return {id: "about", el, show() {}, hide() {}};
}
