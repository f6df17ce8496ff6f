// An independent client of ssx's Foxglove server: Foxglove's own @foxglove/ws-protocol
// (FoxgloveClient, npm) over the `ws` package's WebSocket, and @mcap/core for the recording it is
// compared with.
//   node foxglove_client.mjs live URL SECONDS ROBOT
//     connects, takes the server's information and channels, subscribes to /tf, /scene,
//     /ssx/timing, /ssx/sensors, /ssx/commands, /ssx/run and ROBOT's /ROBOT/odom, /ROBOT/imu,
//     /ROBOT/command, /ROBOT/sensors and /ROBOT/metrics, and after SECONDS prints
//     as JSON what came: the information, the channels (topic, encoding, schema name, whether the
//     schema parses), the time messages, and each channel's messages decoded (time, JSON value).
//   node foxglove_client.mjs tf FILE
//     prints the /tf messages of the recording FILE as JSON: [[time ns, {frame: [x, y, z]}], ...]
import wsProtocol from "@foxglove/ws-protocol";  // (CommonJS for Node.js: its exports through the default)
import { McapIndexedReader } from "@mcap/core";
import { decompress } from "fzstd";
import { open } from "node:fs/promises";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

const [mode, ...args] = process.argv.slice(2);
const decoder = new TextDecoder();

if (mode === "live") {
  const [url, seconds, robot] = args;
  const wanted = ["/tf", "/scene", "/ssx/timing", "/ssx/sensors", "/ssx/commands", "/ssx/run", `/${robot}/odom`,
                  `/${robot}/imu`, `/${robot}/command`, `/${robot}/sensors`, `/${robot}/metrics`];
  const out = { serverInfo: null, channels: [], times: 0, lastTime: null, messages: {}, statuses: [], badMessages: 0 };
  const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const topics = new Map();  // subscription id -> topic
  client.on("serverInfo", (info) => (out.serverInfo = info));
  client.on("status", (s) => out.statuses.push(s));
  client.on("error", (e) => {
    console.error(`client error: ${e}`);
    process.exit(1);
  });
  client.on("advertise", (channels) => {
    for (const c of channels) {
      let schemaParses = true;
      try {
        JSON.parse(c.schema);
      } catch {
        schemaParses = false;
      }
      out.channels.push({ id: c.id, topic: c.topic, encoding: c.encoding, schemaName: c.schemaName, schemaEncoding: c.schemaEncoding, schemaParses });
      if (wanted.includes(c.topic)) topics.set(client.subscribe(c.id), c.topic);
    }
  });
  client.on("time", (t) => {
    out.times++;
    out.lastTime = t.timestamp.toString();
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const topic = topics.get(subscriptionId);
    let value;
    try {
      value = JSON.parse(decoder.decode(data));
    } catch {
      out.badMessages++;
      return;
    }
    (out.messages[topic] ??= []).push([timestamp.toString(), value]);
  });
  setTimeout(() => {
    client.close();
    // (the whole of it before exiting: a pipe takes it in pieces)
    process.stdout.write(JSON.stringify(out) + "\n", () => process.exit(0));
  }, Number(seconds) * 1000);
} else if (mode === "tf") {
  const handle = await open(args[0], "r");
  const readable = {
    size: async () => BigInt((await handle.stat()).size),
    read: async (offset, length) => {
      const buffer = new Uint8Array(Number(length));
      await handle.read(buffer, 0, Number(length), Number(offset));
      return buffer;
    },
  };
  const reader = await McapIndexedReader.Initialize({
    readable,
    decompressHandlers: { zstd: (data, size) => decompress(data, new Uint8Array(Number(size))) },
  });
  const samples = [];
  for await (const m of reader.readMessages({ topics: ["/tf"] })) {
    const frames = {};
    for (const t of JSON.parse(decoder.decode(m.data)).transforms)
      frames[t.child_frame_id] = [t.translation.x, t.translation.y, t.translation.z];
    samples.push([m.logTime.toString(), frames]);
  }
  console.log(JSON.stringify(samples));
} else {
  console.error("usage: node foxglove_client.mjs live URL SECONDS ROBOT | tf FILE");
  process.exit(2);
}
