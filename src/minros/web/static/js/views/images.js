// Images: every sensor_msgs/Image and CompressedImage topic as a live picture, from the
// server's MJPEG endpoint (/stream?topic=..., web_video_server's), and the windows of
// headless cv2.imshow calls (/imshow/<window>). A picture streams only while shown.

import {formatRate, h} from "../ui.js";
import {serverUrl} from "../conn.js";

const IMAGE_TYPES = new Set(["sensor_msgs/Image", "sensor_msgs/CompressedImage"]);
/** pictures that start streaming by themselves (more are one click away) */
const AUTO_SHOW = 4;

export function createImagesView(app) {
  const grid = h("div", {class: "image-grid"});
  const empty = h("p", {class: "muted"}, "No image topics yet. Publish a sensor_msgs/Image, or call cv2.imshow in a node " +
    "(OpenCV without a GUI): its windows appear here as /imshow/<window>.");
  const el = h("section", {}, h("div", {class: "toolbar"}, h("span", {class: "muted"},
    "Pictures come from /stream (MJPEG); open one alone: "), h("a", {href: serverUrl("/streams"), target: "_blank"}, "/streams")),
    empty, grid);
  const cards = new Map();  // topic -> {card, img, on, rate}
  let visible = false;
  let timer = null;

  function imageTopics() {
    const topics = app.graph.topics.filter((t) => IMAGE_TYPES.has(t.type) && t.publishers.length);
    // imshow windows last, each group by name
    return topics.sort((a, b) => (a.name.startsWith("/imshow/") - b.name.startsWith("/imshow/")) || a.name.localeCompare(b.name));
  }

  function render() {
    const topics = imageTopics();
    empty.hidden = topics.length > 0;
    const names = new Set(topics.map((t) => t.name));
    for (const [name, entry] of cards) {
      if (!names.has(name)) {
        stream(entry, false);
        entry.card.remove();
        cards.delete(name);
      }
    }
    topics.forEach((topic, index) => {
      if (cards.has(topic.name)) return;
      const img = h("img", {alt: topic.name, class: "stream"});
      const rate = h("span", {class: "muted"});
      const toggle = h("button", {class: "small", onclick: () => stream(entry, !entry.on)});
      const card = h("figure", {class: "image-card", "data-topic": topic.name}, img,
        h("figcaption", {}, h("code", {}, topic.name), " ", h("span", {class: "muted"}, topic.type.split("/")[1]),
          topic.name.startsWith("/imshow/") ? h("span", {class: "badge"}, "imshow") : null, " ", rate, " ", toggle));
      const entry = {card, img, toggle, rate, on: false, topic: topic.name, wanted: index < AUTO_SHOW};
      cards.set(topic.name, entry);
      grid.append(card);
      stream(entry, entry.wanted && visible);
    });
    app.watchStats("images", visible ? topics.map((t) => t.name) : null);
  }

  function stream(entry, on) {
    entry.on = on;
    if (visible) entry.wanted = on;
    entry.toggle.textContent = on ? "Stop" : "Show";
    // an <img> on /stream keeps one MJPEG connection; removing the src closes it
    if (on) entry.img.src = serverUrl("/stream", {topic: entry.topic, quality: "80"});
    else entry.img.removeAttribute("src");
    entry.card.classList.toggle("off", !on);
  }

  function updateRates() {
    for (const entry of cards.values()) {
      const stat = app.stats[entry.topic];
      entry.rate.textContent = stat && stat.hz !== null ? `${formatRate(stat.hz)} Hz` : "";
    }
  }

  app.onGraph(() => { if (visible) render(); });

  return {
    id: "images", el,
    show() {
      visible = true;
      render();
      for (const entry of cards.values()) stream(entry, entry.wanted);
      timer = setInterval(updateRates, 1000);
    },
    hide() {
      visible = false;
      clearInterval(timer);
      for (const entry of cards.values()) stream(entry, false);
      app.watchStats("images", null);
    },
  };
}
