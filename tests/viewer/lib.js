// Shared pieces of the viewer tests: clients and decoders that no one here wrote
// (@foxglove/ws-protocol, @foxglove/rosmsg, @foxglove/rosmsg2-serialization), and checks.
// The npm packages come from scripts/test-tools (NODE_PATH), never from the repository.
'use strict';
const path = require('path');

const { FoxgloveClient } = require('@foxglove/ws-protocol');
const { WebSocket } = require('ws');
const rosmsg = require('@foxglove/rosmsg');
const { MessageReader } = require('@foxglove/rosmsg2-serialization');
// The built-in page's own decoder, checked against the reference one on every message.
const pageCdr = require(path.join(__dirname, '..', '..', 'onboard', 'web', 'cdr.js'));

function fail(message) {
  console.error('viewer test: FAIL: ' + message);
  process.exit(1);
}
function check(ok, message) {
  if (!ok) fail(message);
}
function log(message) {
  console.log('viewer test: ' + message);
}

// A FoxgloveClient over node's ws, resolved once the server's first advertise came.
function connect(url) {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const channels = new Map();
  client.on('advertise', (list) => list.forEach((c) => channels.set(c.id, c)));
  client.on('unadvertise', (ids) => ids.forEach((id) => channels.delete(id)));
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error('no advertise from ' + url + ' in 10 s')), 10000);
    client.on('error', (e) => reject(e));
    let info = null;
    client.on('serverInfo', (i) => (info = i));
    client.on('advertise', () => {
      clearTimeout(timer);
      setTimeout(() => resolve({ ws, client, channels, info }), 300); // more advertise messages
    });
  });
}

// The reference decoder of a channel: its ros2msg schema parsed by @foxglove/rosmsg.
function referenceDecoder(channel) {
  check(channel.encoding === 'cdr', channel.topic + ': encoding ' + channel.encoding);
  check(channel.schemaEncoding === 'ros2msg', channel.topic + ': schemaEncoding ' + channel.schemaEncoding);
  let reader;
  try {
    reader = new MessageReader(rosmsg.parse(channel.schema, { ros2: true }));
  } catch (e) {
    fail(channel.topic + ' (' + channel.schemaName + '): @foxglove/rosmsg cannot parse the schema: ' + e.message);
  }
  return (bytes) => {
    const msg = reader.readMessage(bytes);
    const trailing = bytes.byteLength - reader.lastReadByteLength();
    if (trailing > 3) throw new Error(trailing + ' bytes after the message');
    return msg;
  };
}

function pageDecoder(channel) {
  return pageCdr.makeDecoder(channel.schema, channel.schemaName);
}

// Deep equality of a reference-decoded message and the page's (bigints as numbers, typed arrays
// and plain arrays element by element, NaN equal to NaN).
function sameMessage(a, b, where) {
  where = where || '';
  const num = (v) => (typeof v === 'bigint' ? Number(v) : v);
  a = num(a);
  b = num(b);
  if (typeof a === 'number' && typeof b === 'number') {
    return a === b || (Number.isNaN(a) && Number.isNaN(b)) ? null : where + ': ' + a + ' vs ' + b;
  }
  const isList = (v) => Array.isArray(v) || ArrayBuffer.isView(v);
  if (isList(a) || isList(b)) {
    if (!isList(a) || !isList(b) || a.length !== b.length) return where + ': lists differ in length';
    for (let i = 0; i < a.length; ++i) {
      const d = sameMessage(a[i], b[i], where + '[' + i + ']');
      if (d) return d;
    }
    return null;
  }
  if (a && typeof a === 'object' && b && typeof b === 'object') {
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    for (const k of keys) {
      const d = sameMessage(a[k], b[k], where + '.' + k);
      if (d) return d;
    }
    return null;
  }
  return a === b ? null : where + ': ' + JSON.stringify(a) + ' vs ' + JSON.stringify(b);
}

// A whole JPEG: SOI first, EOI last, and a start-of-frame segment with its size.
function jpegSize(bytes) {
  const n = bytes.length;
  if (n < 4 || bytes[0] !== 0xff || bytes[1] !== 0xd8) return null;
  if (bytes[n - 2] !== 0xff || bytes[n - 1] !== 0xd9) return null;
  let o = 2;
  while (o + 9 < n) {
    if (bytes[o] !== 0xff) return null;
    const marker = bytes[o + 1];
    if (marker === 0xff) {
      o += 1;
      continue;
    }
    const length = (bytes[o + 2] << 8) | bytes[o + 3];
    const sof = marker >= 0xc0 && marker <= 0xcf && marker !== 0xc4 && marker !== 0xc8 && marker !== 0xcc;
    if (sof) return { height: (bytes[o + 5] << 8) | bytes[o + 6], width: (bytes[o + 7] << 8) | bytes[o + 8] };
    if (marker === 0xda) return null; // scan data before any frame header
    o += 2 + length;
  }
  return null;
}

function topicIs(topic, suffix) {
  return ('/' + topic.replace(/^\/+/, '')).endsWith(suffix);
}

// "--key value" arguments.
function args() {
  const out = {};
  const argv = process.argv.slice(2);
  for (let i = 0; i < argv.length; i += 2) out[argv[i].replace(/^--/, '')] = argv[i + 1];
  return out;
}

module.exports = { connect, referenceDecoder, pageDecoder, sameMessage, jpegSize, topicIs, args, fail, check, log };

// An 8-bit RGB or RGBA PNG (what chromium writes) -> {width, height, channels, pixels}.
function decodePng(buffer) {
  const zlib = require('zlib');
  check(buffer.readUInt32BE(0) === 0x89504e47, 'not a PNG');
  let o = 8, width = 0, height = 0, type = 0;
  const idat = [];
  while (o < buffer.length) {
    const length = buffer.readUInt32BE(o);
    const name = buffer.toString('latin1', o + 4, o + 8);
    const body = buffer.subarray(o + 8, o + 8 + length);
    if (name === 'IHDR') {
      width = body.readUInt32BE(0);
      height = body.readUInt32BE(4);
      check(body[8] === 8 && (body[9] === 2 || body[9] === 6) && body[12] === 0, 'PNG: not 8-bit RGB(A), not interlaced');
      type = body[9];
    } else if (name === 'IDAT') {
      idat.push(body);
    }
    o += 12 + length;
  }
  const channels = type === 6 ? 4 : 3;
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = Buffer.alloc(stride * height);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const left = x >= channels ? pixels[y * stride + x - channels] : 0;
      const up = y > 0 ? pixels[(y - 1) * stride + x] : 0;
      const upLeft = y > 0 && x >= channels ? pixels[(y - 1) * stride + x - channels] : 0;
      let v = line[x];
      if (filter === 1) v += left;
      else if (filter === 2) v += up;
      else if (filter === 3) v += (left + up) >> 1;
      else if (filter === 4) {
        const p = left + up - upLeft;
        const pa = Math.abs(p - left), pb = Math.abs(p - up), pc = Math.abs(p - upLeft);
        v += pa <= pb && pa <= pc ? left : pb <= pc ? up : upLeft;
      }
      pixels[y * stride + x] = v & 255;
    }
  }
  return { width, height, channels, pixels };
}

// names and colours of a palette file as semap-export reads it (config/sim-classes.yaml).
function readPalette(file) {
  const text = require('fs').readFileSync(file, 'utf8').replace(/#.*$/gm, '');
  const list = (key) => {
    const m = new RegExp('^' + key + ':\\s*\\[([^\\]]*)\\]', 'm').exec(text);
    check(m, file + ': no ' + key + ' list');
    return m[1].split(',').map((s) => s.trim()).filter((s) => s !== '');
  };
  const names = list('names');
  const colors = list('colors').map(Number);
  check(colors.length === 3 * names.length, file + ': ' + names.length + ' names, ' + colors.length + ' colour values');
  return names.map((name, i) => ({ name, rgb: colors.slice(3 * i, 3 * i + 3) }));
}

module.exports.decodePng = decodePng;
module.exports.readPalette = readPalette;
