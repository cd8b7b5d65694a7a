// roslib's TFClient (the tf2_web_republisher action) against `minros web`: prints one
// RESULT line with the transforms each subscribed frame received.
//   node tfclient.mjs WS_URL SECONDS
import { Ros, TFClient } from "roslib";

const [url, seconds] = process.argv.slice(2);
const ros = new Ros({ url });
const got = { arm: [], moving: [] };
ros.on("connection", () => {
  const tf = new TFClient({ ros, fixedFrame: "base_link", angularThres: 0.01, transThres: 0.1, rate: 10 });
  for (const frame of Object.keys(got)) {
    tf.subscribe(frame, (t) => got[frame].push([t.translation.x, t.translation.y, t.translation.z,
      t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w]));
  }
  setTimeout(() => {
    console.log("RESULT " + JSON.stringify(got));
    tf.dispose();
    ros.close();
    process.exit(0);
  }, Number(seconds) * 1000);
});
ros.on("error", (e) => { console.log("ERROR " + e); process.exit(1); });
