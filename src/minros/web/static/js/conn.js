// The page's one WebSocket to minros web: rosbridge v2 ops plus the page's own ops
// (subprotocol minros.page.v1; see minros/web/page.py for the list).
//
//   const conn = new Connection();            // ws://<this host>/ with ?token= if the page has one
//   conn.on("graph", (msg) => ...);           // pushed frames, by op
//   const reply = await conn.request("plot", {expr: "/turtle1/pose/x"});  // rejects with the error text
//   const off = conn.subscribe("/turtle1/pose", "turtlesim/Pose", (msg) => ...);  // rosbridge
//   conn.publish("/turtle1/cmd_vel", "geometry_msgs/Twist", {linear: {x: 2}});
//   const values = await conn.callService("/spawn", {x: 1, y: 2});
//
// It reconnects by itself (backoff up to 5 s) and replays what it was asked to keep (watches,
// subscriptions) through the "open" handlers each view registers.
//
// Binary frames (the 3D view's clouds, scans and maps) are a JSON header and arrays: a uint32
// (little-endian) header length, the header, zeros to a multiple of 8, then the arrays the
// header's `buffers` list (name, numpy type, offset from the data's start, length). They are
// emitted by their header's op like text frames, with `arrays` (typed arrays over the frame,
// no copy).
//
// The socket is read on the page's thread. Reading it in a Web Worker (handing binary frames
// over, newest first) was measured with a 100,000-point cloud at 10 Hz in Debian's chromium on
// SwiftShader (tests/integration/test_page_3d.py, MINROS_3D_MAX_POINTS=0): no more clouds taken,
// and the turning camera drew 1-5 frames a second instead of 8-12 (the worker's reading competes
// with the software renderer for the CPU; on the page's thread a busy page reads less and the
// server drops what it cannot send, as it should).

export const SUBPROTOCOL = "minros.page.v1";

const TYPED_ARRAYS = {f4: Float32Array, f8: Float64Array, u1: Uint8Array, i1: Int8Array,
                      u2: Uint16Array, i2: Int16Array, u4: Uint32Array, i4: Int32Array};

export function pageToken() {
  return new URLSearchParams(location.search).get("token") || "";
}

/** A URL of this server (path + query) carrying the page's token. */
export function serverUrl(path, params = {}) {
  const query = new URLSearchParams(params);
  const token = pageToken();
  if (token) query.set("token", token);
  const text = query.toString();
  return path + (text ? "?" + text : "");
}

export class Connection {
  constructor(url) {
    const scheme = location.protocol === "https:" ? "wss://" : "ws://";
    this.url = url || scheme + location.host + serverUrl("/");
    this.handlers = new Map();   // op -> Set of callbacks
    this.pending = new Map();    // request id -> {resolve, reject}
    this.topics = new Map();     // rosbridge subscriptions: topic -> {type, callbacks:Set, options}
    this.advertised = new Set();
    this.nextId = 1;
    this.ws = null;
    this.state = "connecting";
    this.retry = 250;
    this.hello = null;
    this.connect();
  }

  connect() {
    const ws = new WebSocket(this.url, [SUBPROTOCOL]);
    ws.binaryType = "arraybuffer";
    this.ws = ws;
    ws.onopen = () => {
      this.retry = 250;
      this.advertised.clear();
      for (const [topic, sub] of this.topics) this._subscribeOp(topic, sub);
    };
    ws.onmessage = (event) => {
      if (typeof event.data === "string") this._receive(event.data);
      else this._receiveBinary(event.data);
    };
    ws.onclose = () => {
      if (this.ws !== ws) return;
      this._setState("disconnected");
      for (const {reject} of this.pending.values()) reject(new Error("connection lost"));
      this.pending.clear();
      setTimeout(() => this.connect(), this.retry);
      this.retry = Math.min(this.retry * 2, 5000);
    };
  }

  _setState(state) {
    this.state = state;
    this._emit("state", {op: "state", state});
  }

  _receive(text) {
    let msg;
    try {
      msg = JSON.parse(text);
    } catch (err) {
      console.error("minros web sent something that is not JSON", err);
      return;
    }
    if (msg.op === "hello") {
      this.hello = msg;
      this._setState("connected");
    } else if (msg.op === "reply" || (msg.op === "service_response" && this.pending.has(msg.id))) {
      const waiting = this.pending.get(msg.id);
      if (waiting) {
        this.pending.delete(msg.id);
        if (msg.op === "service_response") {
          if (msg.result) waiting.resolve(msg.values);
          else waiting.reject(new Error(typeof msg.values === "string" ? msg.values : "the service call failed"));
        } else if (msg.error !== undefined) {
          waiting.reject(new Error(msg.error));
        } else {
          waiting.resolve(msg);
        }
      }
      return;
    } else if (msg.op === "publish") {
      const sub = this.topics.get(msg.topic);
      if (sub) for (const cb of sub.callbacks) cb(msg.msg);
      return;
    } else if (msg.op === "status" && msg.id !== undefined && this.pending.has(msg.id)) {
      const waiting = this.pending.get(msg.id);
      this.pending.delete(msg.id);
      waiting.reject(new Error(msg.msg));
      return;
    }
    this._emit(msg.op, msg);
  }

  _receiveBinary(buffer) {
    let msg;
    try {
      const length = new DataView(buffer).getUint32(0, true);
      msg = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 4, length)));
      const base = 4 + length + ((8 - ((4 + length) % 8)) % 8);
      msg.arrays = {};
      for (const entry of msg.buffers || []) {
        const Type = TYPED_ARRAYS[entry.type];
        if (!Type) throw new Error(`unknown array type ${entry.type}`);
        msg.arrays[entry.name] = new Type(buffer, base + entry.offset, entry.length);
      }
    } catch (err) {
      console.error("minros web sent a binary frame the page cannot read", err);
      return;
    }
    this._emit(msg.op, msg);
  }

  _emit(op, msg) {
    const set = this.handlers.get(op);
    if (!set) return;
    for (const cb of [...set]) {
      try {
        cb(msg);
      } catch (err) {
        console.error(`handler of ${op} failed`, err);
      }
    }
  }

  /** Call cb for every pushed frame of this op; returns a function that stops it. */
  on(op, cb) {
    if (!this.handlers.has(op)) this.handlers.set(op, new Set());
    this.handlers.get(op).add(cb);
    return () => this.handlers.get(op).delete(cb);
  }

  /** Run cb now if connected, and after every (re)connection. */
  onOpen(cb) {
    if (this.state === "connected") cb();
    return this.on("hello", () => cb());
  }

  send(msg) {
    if (this.ws && this.ws.readyState === WebSocket.OPEN) {
      this.ws.send(JSON.stringify(msg));
      return true;
    }
    return false;
  }

  newId(prefix = "r") {
    return `${prefix}${this.nextId++}`;
  }

  /** A page op that gets one reply: resolves with it, rejects with its error text. */
  request(op, fields = {}, timeoutMs = 15000) {
    const id = fields.id ?? this.newId(op + ":");
    return new Promise((resolve, reject) => {
      if (!this.send({op, id, ...fields})) {
        reject(new Error("not connected to minros web"));
        return;
      }
      this.pending.set(id, {resolve, reject});
      setTimeout(() => {
        if (this.pending.delete(id)) reject(new Error(`no answer to ${op} within ${timeoutMs / 1000} s`));
      }, timeoutMs);
    });
  }

  // -- rosbridge -------------------------------------------------------------------------

  subscribe(topic, type, callback, options = {}) {
    let sub = this.topics.get(topic);
    if (!sub) {
      sub = {type, callbacks: new Set(), options};
      this.topics.set(topic, sub);
      this._subscribeOp(topic, sub);
    }
    sub.callbacks.add(callback);
    return () => {
      sub.callbacks.delete(callback);
      if (!sub.callbacks.size && this.topics.get(topic) === sub) {
        this.topics.delete(topic);
        this.send({op: "unsubscribe", topic});
      }
    };
  }

  _subscribeOp(topic, sub) {
    const msg = {op: "subscribe", topic, queue_length: 1, ...sub.options};
    if (sub.type) msg.type = sub.type;
    this.send(msg);
  }

  publish(topic, type, msg) {
    if (!this.advertised.has(topic) && type) {
      this.send({op: "advertise", topic, type});
      this.advertised.add(topic);
    }
    return this.send({op: "publish", topic, msg});
  }

  /** Resolves with the response's values; every view hears of the call ("service_called"). */
  async callService(service, args = {}, timeoutMs = 15000) {
    const values = await this.request("call_service", {service, args}, timeoutMs);
    this._emit("service_called", {op: "service_called", service, args, values});
    return values;
  }

  /** A rosapi service (/rosapi/<name>) through rosbridge. */
  rosapi(name, args = {}) {
    return this.callService("/rosapi/" + name, args);
  }
}
