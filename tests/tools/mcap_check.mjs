// An independent reader of ssx's recordings: Foxglove's @mcap/core (npm), with fzstd for the zstd
// chunks. Reads FILE twice, once through its summary and index (McapIndexedReader) and once record
// by record from the start (McapStreamReader, which checks every CRC), and prints what it found as
// JSON: channels with their schemas and message counts, the first and last message times,
// attachments and metadata, and whether the two reads agree. JSON channels are parsed, message by
// message, and their JSON Schemas too; of Foxglove's /tf and /scene it prints what they hold.
//   node mcap_check.mjs FILE
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { decompress } from "fzstd";
import { open, readFile } from "node:fs/promises";

const file = process.argv[2];
const decompressHandlers = { zstd: (data, size) => decompress(data, new Uint8Array(Number(size))) };

const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, length) => {
    const buffer = new Uint8Array(Number(length));
    await handle.read(buffer, 0, Number(length), Number(offset));
    return buffer;
  },
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const channels = {};
for (const [id, c] of indexed.channelsById) {
  const schema = indexed.schemasById.get(c.schemaId);
  channels[c.topic] = { id, messageEncoding: c.messageEncoding, schema: schema ? schema.name : null, count: 0 };
  if (schema && schema.encoding === "jsonschema") {
    try {
      channels[c.topic].schemaTitle = JSON.parse(new TextDecoder().decode(schema.data)).title;
    } catch (e) {
      channels[c.topic].schemaError = String(e);
    }
  }
}
// what the JSON channels hold
const json = { badMessages: 0, tfSizes: [], tfFrames: null, tfParents: [], sceneEntities: null, timingSteps: [], sensorArtifacts: null };
let first = null, last = null, count = 0;
for await (const m of indexed.readMessages()) {
  const topic = indexed.channelsById.get(m.channelId).topic;
  channels[topic].count++;
  const c = channels[topic];
  if (c.firstTime === undefined || m.logTime < BigInt(c.firstTime)) c.firstTime = m.logTime.toString();
  if (c.lastTime === undefined || m.logTime > BigInt(c.lastTime)) c.lastTime = m.logTime.toString();
  count++;
  if (first === null || m.logTime < first) first = m.logTime;
  if (last === null || m.logTime > last) last = m.logTime;
  if (channels[topic].messageEncoding !== "json") continue;
  let value;
  try {
    value = JSON.parse(new TextDecoder().decode(m.data));
  } catch {
    json.badMessages++;
    continue;
  }
  if (topic === "/tf") {
    json.tfSizes.push(value.transforms.length);
    if (json.tfFrames === null) json.tfFrames = value.transforms.map((t) => t.child_frame_id);
    for (const t of value.transforms) if (!json.tfParents.includes(t.parent_frame_id)) json.tfParents.push(t.parent_frame_id);
  } else if (topic === "/scene" && json.sceneEntities === null) {
    json.sceneEntities = value.entities.map((e) => ({
      id: e.id, frame: e.frame_id, locked: e.frame_locked,
      primitives: e.cubes.length + e.spheres.length + e.cylinders.length,
    }));
  } else if (topic === "/ssx/timing") {
    json.timingSteps.push(value.step);
  } else if (topic === "/ssx/sensors" && json.sensorArtifacts === null) {
    json.sensorArtifacts = Object.keys(value).length;
  }
}
const attachments = [];
for await (const a of indexed.readAttachments()) attachments.push({ name: a.name, mediaType: a.mediaType, size: a.data.length });
const metadata = [];
for await (const m of indexed.readMetadata()) metadata.push({ name: m.name, keys: [...m.metadata.keys()].sort() });

// the same file from the start, every record, CRCs checked
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(await readFile(file));
let streamed = 0, footer = false;
for (let r; (r = stream.nextRecord()); ) {
  if (r.type === "Message") streamed++;
  if (r.type === "Footer") footer = true;
}
console.log(JSON.stringify({
  profile: indexed.header.profile,
  library: indexed.header.library,
  channels,
  messages: count,
  streamedMessages: streamed,
  footer,
  done: stream.done(),
  firstTime: first === null ? null : first.toString(),
  lastTime: last === null ? null : last.toString(),
  chunks: indexed.chunkIndexes.length,
  statisticsMessageCount: indexed.statistics ? indexed.statistics.messageCount.toString() : null,
  attachments,
  metadata,
  json,
}));
await handle.close();
