// A Foxglove WebSocket client built from Foxglove's own libraries (@foxglove/ws-protocol for the
// protocol, @foxglove/rosmsg + @foxglove/rosmsg-serialization for ROS 1 payloads), driven by the
// minros web tests and benchmark. Prints one JSON object per line; exits 0 when done, 1 on a
// timeout or error (with a line {"error": ...}).
//
//   node foxglove_client.mjs echo URL TOPIC COUNT
//   node foxglove_client.mjs call URL SERVICE JSON_REQUEST
//   node foxglove_client.mjs publish URL TOPIC JSON_MESSAGE COUNT
//   node foxglove_client.mjs params URL NAME JSON_VALUE
//   node foxglove_client.mjs graph URL NODE
//   node foxglove_client.mjs bench URL TOPIC SECONDS
//   node foxglove_client.mjs urdf URL [URI...]   what Lichtblick's 3D panel does for a robot: the
//        /robot_description parameter, then fetchAsset of each mesh it names (and of URI...)
// FOXGLOVE_CLIENT_ORIGIN=https://app.foxglove.dev sends that Origin, as the hosted app would.
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader, MessageWriter } = require("@foxglove/rosmsg-serialization");
const WebSocket = require("ws");

const [mode, url, ...args] = process.argv.slice(2);
const TIMEOUT_MS = Number(process.env.FOXGLOVE_CLIENT_TIMEOUT_MS ?? 20000);

function out(obj) {
  process.stdout.write(
    JSON.stringify(obj, (_k, v) => {
      if (typeof v === "bigint") return v.toString();
      if (ArrayBuffer.isView(v)) return { bytes: v.byteLength, head: Array.from(v.subarray(0, 8)) };
      return v;
    }) + "\n",
  );
}

function fail(text) {
  out({ error: text });
  process.exit(1);
}

setTimeout(() => fail(`timed out after ${TIMEOUT_MS} ms in mode ${mode}`), TIMEOUT_MS).unref();

// FOXGLOVE_CLIENT_ORIGIN: send the Origin header a page of that site would (the Foxglove or
// Lichtblick web app hosted there), as a browser does
const origin = process.env.FOXGLOVE_CLIENT_ORIGIN;
const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL], origin ? { origin } : {});
ws.binaryType = "arraybuffer";
const client = new FoxgloveClient({ ws });
const channels = new Map();
const serverInfo = new Promise((resolve) => client.on("serverInfo", (info) => {
  out({ serverInfo: info });
  resolve(info);
}));
client.on("status", (status) => out({ status }));
client.on("error", (err) => fail(String(err?.message ?? err)));
client.on("close", () => {
  if (!done) fail("connection closed");
});
let done = false;
function finish() {
  done = true;
  client.close();
  setTimeout(() => process.exit(0), 50);
}

function waitChannel(topic) {
  return new Promise((resolve) => {
    const check = (list) => {
      for (const ch of list) {
        channels.set(ch.id, ch);
        if (ch.topic === topic) resolve(ch);
      }
    };
    client.on("advertise", check);
  });
}

if (mode === "echo" || mode === "bench") {
  const [topic, countOrSeconds] = args;
  const channel = await waitChannel(topic);
  out({ channel });
  const reader = new MessageReader(parse(channel.schema, { ros2: false }));
  const subId = client.subscribe(channel.id);
  if (mode === "echo") {
    let n = 0;
    client.on("message", (event) => {
      // finish() closes asynchronously: messages already in the socket still arrive, not counted
      if (event.subscriptionId !== subId || n >= Number(countOrSeconds)) return;
      const msg = reader.readMessage(new Uint8Array(event.data.buffer, event.data.byteOffset, event.data.byteLength));
      out({ message: msg, receiveTime: event.timestamp.toString(), size: event.data.byteLength });
      if (++n >= Number(countOrSeconds)) finish();
    });
  } else {
    const seconds = Number(countOrSeconds);
    let n = 0;
    let bytes = 0;
    let first = null;
    let last = null;
    let decodedOk = false;
    client.on("message", (event) => {
      if (event.subscriptionId !== subId) return;
      const now = performance.now();
      if (first === null) {
        first = now;
        const msg = reader.readMessage(new Uint8Array(event.data.buffer, event.data.byteOffset, event.data.byteLength));
        decodedOk = msg.width > 0 && msg.data.byteLength === msg.step * msg.height;
        return;
      }
      n += 1;
      bytes += event.data.byteLength;
      last = now;
      if (now - first >= seconds * 1000) {
        out({ bench: { messages: n, seconds: (last - first) / 1000, bytes, hz: n / ((last - first) / 1000), decodedOk } });
        finish();
      }
    });
  }
} else if (mode === "call") {
  const [service, requestJson] = args;
  const found = await new Promise((resolve) => {
    client.on("advertiseServices", (list) => {
      for (const s of list) if (s.name === service) resolve(s);
    });
  });
  const reqSchema = found.request?.schema ?? found.requestSchema;
  const resSchema = found.response?.schema ?? found.responseSchema;
  const writer = new MessageWriter(parse(reqSchema, { ros2: false }));
  const reader = new MessageReader(parse(resSchema, { ros2: false }));
  client.on("serviceCallResponse", (event) => {
    out({ response: reader.readMessage(new Uint8Array(event.data.buffer, event.data.byteOffset, event.data.byteLength)), callId: event.callId });
    finish();
  });
  client.on("serviceCallFailure", (event) => {
    out({ failure: event });
    finish();
  });
  client.sendServiceCallRequest({ serviceId: found.id, callId: 7, encoding: "ros1", data: writer.writeMessage(JSON.parse(requestJson)) });
} else if (mode === "publish") {
  const [topic, messageJson, count] = args;
  const channel = await waitChannel(topic);
  const writer = new MessageWriter(parse(channel.schema, { ros2: false }));
  const id = client.advertise({ topic, encoding: "ros1", schemaName: channel.schemaName });
  const data = writer.writeMessage(JSON.parse(messageJson));
  let n = 0;
  const timer = setInterval(() => {
    client.sendMessage(id, data);
    if (++n >= Number(count)) {
      clearInterval(timer);
      out({ published: n });
      setTimeout(finish, 300);
    }
  }, 100);
} else if (mode === "params") {
  const [name, valueJson] = args;
  await serverInfo;
  client.on("parameterValues", (event) => {
    out({ parameterValues: event });
    if (event.id === "get-1") finish();
  });
  client.setParameters([{ name, value: JSON.parse(valueJson) }], "set-1");
  setTimeout(() => client.getParameters([name], "get-1"), 200);
} else if (mode === "graph") {
  const [node] = args;
  await serverInfo;
  client.on("connectionGraphUpdate", (event) => {
    out({ graph: event });
    const all = [...event.publishedTopics.flatMap((t) => t.publisherIds), ...event.subscribedTopics.flatMap((t) => t.subscriberIds)];
    if (all.includes(node)) finish();
  });
  client.subscribeConnectionGraph();
} else if (mode === "urdf") {
  const { createHash } = await import("node:crypto");
  const info = await serverInfo;
  if (!info.capabilities.includes("assets")) fail("the server does not offer the assets capability");
  const urdf = await new Promise((resolve) => {
    client.on("parameterValues", (event) => {
      if (event.id !== "get-all-params") return;
      const found = event.parameters.find((p) => p.name === "/robot_description");
      resolve(found ? found.value : null);
    });
    client.getParameters([], "get-all-params");  // Lichtblick asks for every parameter
  });
  if (typeof urdf !== "string") fail("no /robot_description string parameter");
  const meshes = [...urdf.matchAll(/<mesh\s+filename="([^"]+)"/g)].map((m) => m[1]);
  out({ robot: { bytes: urdf.length, meshes } });
  const uris = [...meshes, ...args];
  const pending = new Map();
  client.on("fetchAssetResponse", (response) => {
    const uri = pending.get(response.requestId);
    pending.delete(response.requestId);
    const data = response.status === 0 ? new Uint8Array(response.data.buffer, response.data.byteOffset, response.data.byteLength) : null;
    out({ asset: { uri, requestId: response.requestId, status: response.status, error: response.error,
                   bytes: data ? data.byteLength : 0, sha256: data ? createHash("sha256").update(data).digest("hex") : null } });
    if (!pending.size) finish();
  });
  uris.forEach((uri, i) => {
    pending.set(100 + i, uri);
    client.fetchAsset(uri, 100 + i);
  });
  if (!uris.length) finish();
} else {
  fail(`unknown mode ${mode}`);
}
