// @mcap/core (with @mcap/support's decompression) reads an MCAP file semap wrote: header
// profile, schemas, channels, the summary's message counts against the messages read through the
// index and through the streaming reader, every message decoded with @foxglove/rosmsg +
// @foxglove/rosmsg2-serialization from its schema; with --truncate, the file cut off at 60 %
// (a crash) still gives its messages up to the cut to the streaming reader.
//
//   node mcap_read_test.js --file RUN.mcap [--topics /a,/b] [--min-messages N] [--truncate 1]
'use strict';
const fs = require('fs');
const { McapIndexedReader, McapStreamReader } = require('@mcap/core');
const { loadDecompressHandlers } = require('@mcap/support');
const rosmsg = require('@foxglove/rosmsg');
const { MessageReader } = require('@foxglove/rosmsg2-serialization');
const lib = require('./lib.js');
const { check, fail, log } = lib;

const a = lib.args();

function decoderFor(schema, channel) {
  check(schema, channel.topic + ': no schema');
  check(channel.messageEncoding === 'cdr', channel.topic + ': message encoding ' + channel.messageEncoding);
  check(schema.encoding === 'ros2msg', channel.topic + ': schema encoding ' + schema.encoding);
  let reader;
  try {
    reader = new MessageReader(rosmsg.parse(new TextDecoder().decode(schema.data), { ros2: true }));
  } catch (e) {
    fail(channel.topic + ' (' + schema.name + '): @foxglove/rosmsg cannot parse the schema: ' + e.message);
  }
  return (bytes) => {
    const msg = reader.readMessage(bytes);
    const trailing = bytes.byteLength - reader.lastReadByteLength();
    if (trailing > 3) throw new Error(trailing + ' bytes after the message');
    return msg;
  };
}

// Streaming read of bytes: {messages per channel id, error (a cut-off file)}.
function streamRead(bytes, decompressHandlers) {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(bytes);
  const counts = new Map();
  let error = null;
  try {
    for (let r; (r = reader.nextRecord()) !== undefined;) {
      if (r.type === 'Message') counts.set(r.channelId, (counts.get(r.channelId) || 0) + 1);
    }
  } catch (e) {
    error = e.message;
  }
  return { counts, error, done: reader.done() };
}

async function main() {
  const bytes = new Uint8Array(fs.readFileSync(a.file));
  const decompressHandlers = await loadDecompressHandlers();
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  log(a.file + ': ' + bytes.length + ' bytes, profile "' + reader.header.profile + '", library "' +
    reader.header.library + '", ' + reader.chunkIndexes.length + ' chunks (' +
    [...new Set(reader.chunkIndexes.map((c) => c.compression || 'none'))].join(', ') + ')');
  check(reader.header.profile === 'ros2', 'profile "' + reader.header.profile + '", not ros2');
  check(reader.statistics, 'no statistics record in the summary');
  check(reader.chunkIndexes.length > 0, 'no chunk index');

  const decoders = new Map();
  for (const [id, channel] of reader.channelsById) {
    const schema = reader.schemasById.get(channel.schemaId);
    decoders.set(id, decoderFor(schema, channel));
  }
  const counts = new Map();
  let lastTime = -1n, outOfOrder = 0;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const channel = reader.channelsById.get(m.channelId);
    try {
      decoders.get(m.channelId)(m.data);
    } catch (e) {
      fail(channel.topic + ': message ' + (counts.get(m.channelId) || 0) + ' does not decode: ' + e.message);
    }
    counts.set(m.channelId, (counts.get(m.channelId) || 0) + 1);
    if (m.logTime < lastTime) outOfOrder++;
    lastTime = m.logTime;
  }
  check(outOfOrder === 0, outOfOrder + ' messages out of log-time order');
  let total = 0;
  for (const [id, channel] of reader.channelsById) {
    const schema = reader.schemasById.get(channel.schemaId);
    const n = counts.get(id) || 0;
    const stated = Number(reader.statistics.channelMessageCounts.get(id) || 0n);
    log('  ' + channel.topic + ' (' + schema.name + ', ' + channel.messageEncoding + '/' + schema.encoding + '): ' + n + ' messages');
    check(n === stated, channel.topic + ': ' + n + ' messages read, the statistics say ' + stated);
    total += n;
  }
  check(total === Number(reader.statistics.messageCount), total + ' messages read, the statistics say ' + reader.statistics.messageCount);
  check(total >= Number(a['min-messages'] || 1), 'only ' + total + ' messages');
  for (const t of (a.topics || '').split(',').filter((s) => s)) {
    const ids = [...reader.channelsById].filter(([, c]) => lib.topicIs(c.topic, t)).map(([id]) => id);
    check(ids.length > 0, 'no channel ' + t);
    check(ids.some((id) => counts.get(id) > 0), 'no message on ' + t);
  }

  // The same file through the streaming reader (no index).
  const streamed = streamRead(bytes, decompressHandlers);
  check(!streamed.error && streamed.done, 'streaming read: ' + (streamed.error || 'not at the end'));
  for (const [id, n] of counts) check(streamed.counts.get(id) === n, 'streaming read: channel ' + id + ' ' + streamed.counts.get(id) + ' vs ' + n);

  if (a.truncate) {
    const cut = streamRead(bytes.subarray(0, Math.floor(bytes.length * 0.6)), decompressHandlers);
    const n = [...cut.counts.values()].reduce((s, v) => s + v, 0);
    log('cut off at 60 %: ' + n + ' of ' + total + ' messages read' + (cut.error ? ' (then: ' + cut.error + ')' : ''));
    check(n > 0, 'nothing readable from the file cut off at 60 %');
  }
  log('PASS: ' + total + ' messages on ' + reader.channelsById.size + ' channels, every one decoded');
}

main().catch((e) => fail(e.stack || e.message));
