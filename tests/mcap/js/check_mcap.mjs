// Independent check of avs::mcap files (issue 7 acceptance): read them with the official MCAP
// TypeScript library (@mcap/core), once through the index (McapIndexedReader, summary + chunk
// indexes) and once as a stream (McapStreamReader, CRCs validated), decode every message with
// the ros2msg schema stored in the file (@foxglove/rosmsg + @foxglove/rosmsg2-serialization),
// and compare with the values the C++ side published (expected.json).
//
// usage: node check_mcap.mjs expected.json file.mcap [file.mcap ...]
import { readFile } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { decompress as zstdDecompress } from "fzstd";
import lz4 from "lz4js";

const decompressHandlers = {
  lz4: (buffer, size) => Uint8Array.from(lz4.decompress(buffer, Number(size))),
  zstd: (buffer, size) => zstdDecompress(buffer, new Uint8Array(Number(size))),
};

function normalise(value) {
  if (value instanceof Uint8Array) return Array.from(value);
  if (typeof value === "bigint") return value.toString();
  if (Array.isArray(value)) return value.map(normalise);
  if (value !== null && typeof value === "object") {
    const out = {};
    for (const key of Object.keys(value).sort()) out[key] = normalise(value[key]);
    return out;
  }
  return value;
}

function same(a, b) {
  return JSON.stringify(normalise(a)) === JSON.stringify(normalise(b));
}

function makeDecoders(schemasById, channelsById) {
  const decoders = new Map();
  for (const [id, channel] of channelsById) {
    const schema = schemasById.get(channel.schemaId);
    if (!schema) throw new Error(`channel ${channel.topic} has no schema`);
    if (schema.encoding !== "ros2msg") throw new Error(`schema ${schema.name}: ${schema.encoding}`);
    if (channel.messageEncoding !== "cdr") throw new Error(`channel ${channel.topic}: encoding`);
    if (!channel.metadata.get("offered_qos_profiles")) {
      throw new Error(`channel ${channel.topic}: no offered_qos_profiles`);
    }
    const text = new TextDecoder().decode(schema.data);
    const definitions = parseMessageDefinition(text, { ros2: true });
    decoders.set(id, { topic: channel.topic, type: schema.name, reader: new MessageReader(definitions) });
  }
  return decoders;
}

function compare(file, how, got, expected) {
  if (got.length !== expected.length) {
    throw new Error(`${file} (${how}): ${got.length} messages, expected ${expected.length}`);
  }
  for (let i = 0; i < expected.length; i++) {
    const e = expected[i];
    const g = got[i];
    const where = `${file} (${how}) message ${i} on ${e.topic}`;
    if (g.topic !== e.topic) throw new Error(`${where}: topic ${g.topic}`);
    if (g.type !== e.type) throw new Error(`${where}: type ${g.type}`);
    if (g.logTime.toString() !== e.log_time) throw new Error(`${where}: log_time ${g.logTime}`);
    if (g.publishTime.toString() !== e.publish_time) {
      throw new Error(`${where}: publish_time ${g.publishTime}`);
    }
    if (g.sequence !== e.sequence) throw new Error(`${where}: sequence ${g.sequence}`);
    if (!same(g.value, e.value)) {
      throw new Error(
        `${where}: decoded ${JSON.stringify(normalise(g.value)).slice(0, 300)} expected ` +
          `${JSON.stringify(e.value).slice(0, 300)}`,
      );
    }
  }
}

async function readIndexed(bytes) {
  const readable = {
    size: async () => BigInt(bytes.byteLength),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  if (reader.header.profile !== "ros2") throw new Error(`profile ${reader.header.profile}`);
  if (!reader.statistics) throw new Error("no Statistics record");
  if (reader.chunkIndexes.length === 0) throw new Error("no Chunk Index records");
  const decoders = makeDecoders(reader.schemasById, reader.channelsById);
  const out = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const d = decoders.get(m.channelId);
    out.push({ ...m, topic: d.topic, type: d.type, value: d.reader.readMessage(m.data) });
  }
  const total = [...reader.statistics.channelMessageCounts.values()].reduce((a, b) => a + b, 0n);
  if (total !== BigInt(out.length)) throw new Error(`Statistics count ${total} != ${out.length}`);
  return out;
}

function readStream(bytes) {
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const schemas = new Map();
  const channels = new Map();
  const raw = [];
  let sawDataEnd = false;
  let sawFooter = false;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type === "Message") raw.push(record);
    if (record.type === "DataEnd") sawDataEnd = true;
    if (record.type === "Footer") sawFooter = true;
  }
  if (!stream.done()) throw new Error("stream reader did not reach the end magic");
  if (!sawDataEnd || !sawFooter) throw new Error("missing Data End or Footer");
  const decoders = makeDecoders(schemas, channels);
  return raw.map((m) => {
    const d = decoders.get(m.channelId);
    return { ...m, topic: d.topic, type: d.type, value: d.reader.readMessage(m.data) };
  });
}

const [expectedPath, ...files] = process.argv.slice(2);
if (!expectedPath || files.length === 0) {
  console.error("usage: node check_mcap.mjs expected.json file.mcap [...]");
  process.exit(2);
}
const expected = JSON.parse(await readFile(expectedPath, "utf8"));
let passed = 0;
let failed = 0;
for (const file of files) {
  const bytes = new Uint8Array(await readFile(file));
  for (const [how, read] of [["indexed", readIndexed], ["stream", readStream]]) {
    try {
      compare(file, how, await read(bytes), expected.messages);
      console.log(`ok   ${file} (${how}): ${expected.messages.length} messages decoded and equal`);
      passed++;
    } catch (error) {
      console.log(`FAIL ${file} (${how}): ${error.message}`);
      failed++;
    }
  }
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
