// Wire: the live trace of XML-RPC calls and connection headers as a numbered sequence, once
// minros has a wire trace (minros trace). Until then this view says so.

import {h} from "../ui.js";

export function createWireView(app) {
  const body = h("div", {class: "wire-placeholder"},
    h("h3", {}, "Wire trace"),
    h("p", {}, "This view will show, as a numbered sequence, every XML-RPC call (registerPublisher, " +
      "publisherUpdate, requestTopic, ...) and every TCPROS connection header of the running system, " +
      "the way ROS courses draw a talker meeting a listener."),
    h("p", {class: "muted"}, "This minros has no wire trace yet, so there is nothing to show: the server " +
      "says so in its hello (wire: false). Meanwhile `minros graph`, the Graph view and rosnode info " +
      "show who is connected to whom."));
  app.conn.onOpen(() => {
    if (app.conn.hello.wire) body.append(h("p", {}, "The server has a wire trace, but this page does not show it yet."));
  });
  return {id: "wire", el: h("section", {}, body), show() {}, hide() {}};
}
