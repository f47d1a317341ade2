// Decode every message of an MCAP file with Foxglove's own readers (@mcap/core, @mcap/support,
// @foxglove/rosmsg, @foxglove/rosmsg2-serialization), as the Foxglove app does for a ros2msg
// schema with cdr messages. Prints one JSON line per message:
//   {"topic", "schema", "logTime", "trailing", "message"}
// Numbers are written as "f:" + the 16 hex digits of their float64 bits (little endian), so
// that NaN, infinities and -0 survive JSON; bigints as "i:" + decimal.
// Usage: node decode.mjs FILE.mcap [TOPIC ...]   (no topics: every topic)
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";

const [path, ...topics] = process.argv.slice(2);
const handle = await open(path, "r");
const size = BigInt((await handle.stat()).size);
const readable = {
  size: async () => size,
  read: async (offset, length) => {
    const buffer = new Uint8Array(Number(length));
    await handle.read(buffer, 0, Number(length), Number(offset));
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({
  readable,
  decompressHandlers: await loadDecompressHandlers(),
});

const bits = new DataView(new ArrayBuffer(8));
function replacer(_key, value) {
  if (typeof value === "number") {
    bits.setFloat64(0, value, true);
    let hex = "";
    for (let i = 0; i < 8; i++) hex += bits.getUint8(i).toString(16).padStart(2, "0");
    return "f:" + hex;
  }
  if (typeof value === "bigint") return "i:" + value.toString();
  if (ArrayBuffer.isView(value)) return Array.from(value);
  return value;
}

const readers = new Map();
for await (const message of reader.readMessages(topics.length ? { topics } : {})) {
  const channel = reader.channelsById.get(message.channelId);
  const schema = reader.schemasById.get(channel.schemaId);
  if (!readers.has(schema.id)) {
    const text = new TextDecoder().decode(schema.data);
    readers.set(schema.id, new MessageReader(parse(text, { ros2: true })));
  }
  const messageReader = readers.get(schema.id);
  const decoded = messageReader.readMessage(message.data);
  process.stdout.write(JSON.stringify({
    topic: channel.topic,
    schema: schema.name,
    logTime: message.logTime,
    trailing: messageReader.lastReadHadTrailingBytes(),
    message: decoded,
  }, replacer) + "\n");
}
await handle.close();
