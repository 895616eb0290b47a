// Compares two recordings topic by topic, message by message (raw message bytes and log times)
// and metadata record by record:
//
//   node cmp_topics.mjs OLD.mcap NEW.mcap
//
// Prints one JSON line per topic {topic, messages, identical} and per metadata record; exit 0.
// Used to say which topics a change of the scene entities moved (recordings/README.md).

import { readFileSync } from "node:fs";

import { McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

async function read(path, decompressHandlers) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(readFileSync(path));
  const channels = new Map();
  const topics = new Map();
  const metadata = new Map();
  let rec;
  while ((rec = reader.nextRecord())) {
    if (rec.type === "Channel") channels.set(rec.id, rec.topic);
    else if (rec.type === "Message") {
      const t = channels.get(rec.channelId);
      if (!topics.has(t)) topics.set(t, []);
      topics.get(t).push([rec.logTime, Buffer.from(rec.data)]);
    } else if (rec.type === "Metadata") metadata.set(rec.name, JSON.stringify([...rec.metadata.entries()].sort()));
  }
  return { topics, metadata };
}

const h = await loadDecompressHandlers();
const [a, b] = await Promise.all(process.argv.slice(2, 4).map((p) => read(p, h)));
const names = [...new Set([...a.topics.keys(), ...b.topics.keys()])].sort();
for (const t of names) {
  const x = a.topics.get(t) ?? [];
  const y = b.topics.get(t) ?? [];
  const identical = x.length === y.length && x.every(([tx, dx], i) => tx === y[i][0] && dx.equals(y[i][1]));
  console.log(JSON.stringify({ topic: t, messages: [x.length, y.length], identical }));
}
for (const m of [...new Set([...a.metadata.keys(), ...b.metadata.keys()])].sort()) {
  console.log(JSON.stringify({ metadata: m, identical: a.metadata.get(m) === b.metadata.get(m) }));
}
