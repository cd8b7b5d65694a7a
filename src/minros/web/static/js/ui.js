// Small DOM helpers shared by the views: element builder, collapsible tree, error lines,
// number formats, and forms generated from message definitions (rosapi TypeDefs).

/** h("div", {class: "x", onclick: fn}, "text", child, [children]) */
export function h(tag, attrs = {}, ...children) {
  const el = document.createElement(tag);
  for (const [key, value] of Object.entries(attrs || {})) {
    if (value === undefined || value === null || value === false) continue;
    if (key.startsWith("on")) el.addEventListener(key.slice(2), value);
    else if (key === "class") el.className = value;
    else if (key === "style" && typeof value === "object") Object.assign(el.style, value);
    else if (key in el && typeof value !== "string") el[key] = value;
    else el.setAttribute(key, value === true ? "" : value);
  }
  append(el, children);
  return el;
}

function append(el, children) {
  for (const child of children) {
    if (child === undefined || child === null || child === false) continue;
    if (Array.isArray(child)) append(el, child);
    else el.append(child instanceof Node ? child : String(child));
  }
}

export function clear(el) {
  while (el.firstChild) el.removeChild(el.firstChild);
  return el;
}

/** Replace el's children (arrays flattened; null, undefined and false skipped). */
export function fill(el, ...children) {
  clear(el);
  append(el, children);
  return el;
}

/** A line under an input that shows an error (or nothing). */
export function errorLine() {
  const el = h("div", {class: "error-line", role: "alert"});
  el.show = (text) => {
    el.textContent = text || "";
    el.classList.toggle("visible", Boolean(text));
  };
  el.ok = (text) => {
    el.textContent = text || "";
    el.classList.remove("visible");
    el.classList.toggle("ok", Boolean(text));
  };
  return el;
}

export function formatRate(hz) {
  if (hz === null || hz === undefined) return "…";
  if (hz === 0) return "0";
  if (hz >= 100) return hz.toFixed(0);
  if (hz >= 10) return hz.toFixed(1);
  return hz.toFixed(2);
}

export function formatBytes(bytesPerSecond, suffix = "/s") {
  if (bytesPerSecond === null || bytesPerSecond === undefined) return "…";
  const units = ["B", "KB", "MB", "GB"];
  let value = bytesPerSecond;
  let unit = 0;
  while (value >= 1000 && unit < units.length - 1) {
    value /= 1000;
    unit++;
  }
  return `${value.toFixed(value >= 100 || unit === 0 ? 0 : 1)} ${units[unit]}${suffix}`;
}

// -- a collapsible tree of JSON values ---------------------------------------------------

/**
 * A tree view that keeps which branches are open across updates: tree.update(value).
 * Branches deeper than `openDepth` start closed.
 */
export function treeView(openDepth = 2) {
  const closed = new Set();
  const opened = new Set();
  const root = h("div", {class: "tree"});
  const render = (value, path, depth) => {
    if (value !== null && typeof value === "object") {
      const isArray = Array.isArray(value);
      const keys = Object.keys(value);
      const isOpen = opened.has(path) || (!closed.has(path) && depth < openDepth);
      const summary = isArray ? `[${keys.length}]` : `{${keys.length}}`;
      const node = h("div", {class: "tree-branch" + (isOpen ? " open" : "")});
      const toggle = h("span", {class: "tree-toggle", onclick: () => {
        if (node.classList.toggle("open")) {
          opened.add(path);
          closed.delete(path);
          if (!body.firstChild) fill();
        } else {
          closed.add(path);
          opened.delete(path);
        }
      }}, summary);
      const body = h("div", {class: "tree-body"});
      const fill = () => {
        for (const key of keys) {
          const child = value[key];
          const leaf = child === null || typeof child !== "object";
          body.append(h("div", {class: "tree-row"}, h("span", {class: "tree-key"}, key + ":"), " ",
                        leaf ? valueSpan(child) : render(child, path + "/" + key, depth + 1)));
        }
      };
      if (isOpen) fill();
      node.append(toggle, body);
      return node;
    }
    return valueSpan(value);
  };
  root.update = (value) => {
    clear(root).append(render(value, "", 0));
  };
  return root;
}

function valueSpan(value) {
  const kind = value === null ? "null" : typeof value;
  return h("span", {class: "tree-value " + kind}, kind === "string" ? JSON.stringify(value) : String(value));
}

// -- forms from message definitions ------------------------------------------------------

const INTS = new Set(["byte", "char", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"]);
const FLOATS = new Set(["float32", "float64"]);

/** The TypeDef of `type` among rosapi's typedefs (matched on the full or the short name). */
function findTypedef(typedefs, type) {
  return typedefs.find((t) => t.type === type) ||
    typedefs.find((t) => t.type.split("/").pop() === type.split("/").pop());
}

/**
 * A form for one message type from rosapi's TypeDefs (message_details,
 * service_request_details). form.value() gives rosbridge JSON values; it throws an Error
 * naming the field whose text is not a value of its type.
 */
export function messageForm(typedefs, type, prefix = "") {
  const typedef = findTypedef(typedefs, type);
  const el = h("div", {class: "msg-form"});
  const getters = [];
  if (!typedef) {
    el.append(h("div", {class: "muted"}, `no definition of ${type}`));
    return Object.assign(el, {value: () => ({})});
  }
  if (!typedef.fieldnames.length) el.append(h("div", {class: "muted"}, "(no fields)"));
  typedef.fieldnames.forEach((name, i) => {
    const fieldType = typedef.fieldtypes[i];
    const arrayLen = typedef.fieldarraylen[i];
    const path = prefix ? `${prefix}.${name}` : name;
    const label = h("label", {class: "field-label", title: `${fieldType}${arrayLen >= 0 ? `[${arrayLen || ""}]` : ""}`},
                    name, h("span", {class: "muted"}, ` ${fieldType}${arrayLen >= 0 ? `[${arrayLen > 0 ? arrayLen : ""}]` : ""}`));
    if (arrayLen >= 0) {
      const input = h("input", {type: "text", placeholder: "[ ] as JSON, e.g. [1, 2]", "data-field": path});
      getters.push([name, () => parseJson(input.value || "[]", path)]);
      el.append(h("div", {class: "field"}, label, input));
    } else if (fieldType === "time" || fieldType === "duration") {
      const secs = h("input", {type: "number", value: "0", step: "1", "data-field": path + ".secs"});
      const nsecs = h("input", {type: "number", value: "0", step: "1", "data-field": path + ".nsecs"});
      getters.push([name, () => ({secs: intValue(secs.value, path + ".secs"), nsecs: intValue(nsecs.value, path + ".nsecs")})]);
      el.append(h("div", {class: "field"}, label, h("span", {class: "pair"}, secs, nsecs)));
    } else if (INTS.has(fieldType) || FLOATS.has(fieldType)) {
      const input = h("input", {type: "number", value: "0", step: FLOATS.has(fieldType) ? "any" : "1", "data-field": path});
      getters.push([name, () => (FLOATS.has(fieldType) ? floatValue(input.value, path) : intValue(input.value, path))]);
      el.append(h("div", {class: "field"}, label, input));
    } else if (fieldType === "bool") {
      const input = h("input", {type: "checkbox", "data-field": path});
      getters.push([name, () => input.checked]);
      el.append(h("div", {class: "field"}, label, input));
    } else if (fieldType === "string") {
      const input = h("input", {type: "text", "data-field": path});
      getters.push([name, () => input.value]);
      el.append(h("div", {class: "field"}, label, input));
    } else {
      const sub = messageForm(typedefs, fieldType, path);
      getters.push([name, () => sub.value()]);
      el.append(h("fieldset", {class: "field-group"}, h("legend", {}, name, h("span", {class: "muted"}, " " + fieldType)), sub));
    }
  });
  el.value = () => Object.fromEntries(getters.map(([name, get]) => [name, get()]));
  return el;
}

function parseJson(text, path) {
  try {
    return JSON.parse(text);
  } catch (err) {
    throw new Error(`${path}: not JSON (${err.message})`);
  }
}

function intValue(text, path) {
  if (text.trim() === "") return 0;
  const value = Number(text);
  if (!Number.isInteger(value)) throw new Error(`${path}: ${JSON.stringify(text)} is not an integer`);
  return value;
}

function floatValue(text, path) {
  if (text.trim() === "") return 0;
  const value = Number(text);
  if (Number.isNaN(value)) throw new Error(`${path}: ${JSON.stringify(text)} is not a number`);
  return value;
}

/** A YAML template of a message type (what `rostopic pub` users type), from TypeDefs. */
export function yamlTemplate(typedefs, type, indent = "") {
  const typedef = findTypedef(typedefs, type);
  if (!typedef || !typedef.fieldnames.length) return "{}";
  const lines = [];
  typedef.fieldnames.forEach((name, i) => {
    const fieldType = typedef.fieldtypes[i];
    if (typedef.fieldarraylen[i] >= 0) lines.push(`${indent}${name}: []`);
    else if (fieldType === "time" || fieldType === "duration") lines.push(`${indent}${name}: {secs: 0, nsecs: 0}`);
    else if (INTS.has(fieldType)) lines.push(`${indent}${name}: 0`);
    else if (FLOATS.has(fieldType)) lines.push(`${indent}${name}: 0.0`);
    else if (fieldType === "bool") lines.push(`${indent}${name}: false`);
    else if (fieldType === "string") lines.push(`${indent}${name}: ''`);
    else {
      const sub = yamlTemplate(typedefs, fieldType, indent + "  ");
      lines.push(sub === "{}" ? `${indent}${name}: {}` : `${indent}${name}:\n${sub}`);
    }
  });
  return lines.join("\n");
}

/** <datalist> of names for an <input list=...>. */
export function datalist(id, names) {
  const list = document.getElementById(id) || h("datalist", {id});
  clear(list).append(...names.map((n) => h("option", {value: n})));
  if (!list.parentNode) document.body.append(list);
  return list;
}
