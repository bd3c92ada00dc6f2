// semap viewer: a ros2msg schema parser and a CDR decoder (XCDR1 as ROS 2 writes it).
//
// The Foxglove WebSocket server advertises each channel with schemaEncoding "ros2msg": the .msg
// text of the type, then each type it uses after a line of '=' and "MSG: pkg/Type". Messages are
// CDR: a 4-byte encapsulation header (0x00 0x01 = little-endian CDR), then the fields in order,
// each primitive aligned to its size (8 at most) counted from the end of that header; strings and
// sequences are a uint32 length first (a string's length counts its trailing NUL); fixed-size
// arrays have no length. Nested messages add no alignment of their own.
//
// Works in a browser (window.SemapCdr) and in node (module.exports), where the tests compare it
// with @foxglove/rosmsg2-serialization on every message the robot sends.
(function (root) {
  'use strict';

  // name -> [size in bytes, DataView getter]
  const PRIMITIVES = {
    bool: [1, 'getUint8'],
    byte: [1, 'getUint8'],
    char: [1, 'getUint8'],
    int8: [1, 'getInt8'],
    uint8: [1, 'getUint8'],
    int16: [2, 'getInt16'],
    uint16: [2, 'getUint16'],
    int32: [4, 'getInt32'],
    uint32: [4, 'getUint32'],
    float32: [4, 'getFloat32'],
    int64: [8, 'getBigInt64'],
    uint64: [8, 'getBigUint64'],
    float64: [8, 'getFloat64'],
  };

  // "pkg/msg/Type" and "pkg/Type" both become "pkg/Type".
  function normalizeName(name) {
    const parts = name.split('/');
    return parts.length === 3 && parts[1] === 'msg' ? parts[0] + '/' + parts[2] : name;
  }

  // One field line: "TYPE NAME [DEFAULT]", TYPE with an optional bound (string<=10) and array
  // suffix ([], [N], [<=N]). Returns null for a constant ("TYPE NAME = VALUE") or a blank line.
  function parseField(line) {
    const m = /^([A-Za-z][\w/]*)(<=\d+)?(\[(<=)?(\d*)\])?\s+([A-Za-z]\w*)\s*(.*)$/.exec(line);
    if (!m) throw new Error('ros2msg: cannot parse line "' + line + '"');
    if (m[7].startsWith('=')) return null; // a constant: not in the message's bytes
    const fixed = m[3] !== undefined && m[4] === undefined && m[5] !== '';
    return {
      name: m[6],
      type: m[1],
      isArray: m[3] !== undefined,
      arrayLength: fixed ? Number(m[5]) : undefined,
    };
  }

  // Parses a ros2msg schema into {root: name, types: {name: [field...]}}, nested type names
  // resolved to their full "pkg/Type".
  function parseRos2msg(text, rootName) {
    const root = normalizeName(rootName);
    const types = {};
    const sections = text.split(/^={10,}[ \t]*$/m);
    sections.forEach(function (section, i) {
      let name = root;
      const fields = [];
      for (const raw of section.split('\n')) {
        const msgLine = /^MSG:\s*(\S+)/.exec(raw.trim());
        if (msgLine) {
          name = normalizeName(msgLine[1]);
          continue;
        }
        const line = raw.replace(/#.*$/, '').trim();
        if (line === '') continue;
        const field = parseField(line);
        if (field) fields.push(field);
      }
      if (i === 0 || name !== root) types[name] = fields;
    });
    // Resolve nested types: a full name, a name in the same package, or "Header".
    for (const [name, fields] of Object.entries(types)) {
      const pkg = name.includes('/') ? name.split('/')[0] : '';
      for (const f of fields) {
        if (PRIMITIVES[f.type] || f.type === 'string' || f.type === 'wstring') continue;
        const candidates = [normalizeName(f.type), pkg + '/' + f.type, 'std_msgs/' + f.type];
        const found = candidates.find((c) => types[c]);
        if (!found) throw new Error('ros2msg: type ' + f.type + ' (in ' + name + ') is not defined');
        f.type = found;
      }
    }
    if (!types[root]) throw new Error('ros2msg: no definition of ' + root);
    return { root: root, types: types };
  }

  class CdrReader {
    constructor(bytes) {
      if (bytes.byteLength < 4) throw new Error('CDR: shorter than its header');
      this.bytes = bytes;
      this.view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      const kind = bytes[1]; // 0 CDR_BE, 1 CDR_LE, 2 PL_CDR_BE, 3 PL_CDR_LE
      this.little = (kind & 1) === 1;
      this.offset = 4;
    }
    align(size) {
      const rel = (this.offset - 4) % size;
      if (rel !== 0) this.offset += size - rel;
    }
    need(n) {
      if (this.offset + n > this.bytes.byteLength) {
        throw new Error('CDR: message ends at ' + this.bytes.byteLength + ', needs ' + (this.offset + n));
      }
    }
    primitive(type) {
      const [size, getter] = PRIMITIVES[type];
      this.align(size);
      this.need(size);
      let v = this.view[getter](this.offset, this.little);
      this.offset += size;
      if (type === 'bool') v = v !== 0;
      else if (size === 8 && typeof v === 'bigint') v = Number(v); // counters and stamps fit
      return v;
    }
    uint32() {
      return this.primitive('uint32');
    }
    string() {
      const length = this.uint32();
      this.need(length);
      const end = this.offset + Math.max(0, length - 1); // without the trailing NUL
      const s = CdrReader.decoder.decode(this.bytes.subarray(this.offset, end));
      this.offset += length;
      return s;
    }
    // uint8/int8/byte/char arrays as typed-array views of the message (no copy).
    bytesOf(type, count) {
      this.need(count);
      const start = this.bytes.byteOffset + this.offset;
      this.offset += count;
      return type === 'int8'
        ? new Int8Array(this.bytes.buffer, start, count)
        : new Uint8Array(this.bytes.buffer, start, count);
    }
  }
  CdrReader.decoder = new TextDecoder('utf-8');

  function readValue(reader, types, type) {
    if (type === 'string') return reader.string();
    if (PRIMITIVES[type]) return reader.primitive(type);
    if (type === 'wstring') throw new Error('CDR: wstring is not supported');
    const out = {};
    for (const f of types[type]) out[f.name] = readField(reader, types, f);
    return out;
  }

  function readField(reader, types, field) {
    if (!field.isArray) return readValue(reader, types, field.type);
    const count = field.arrayLength !== undefined ? field.arrayLength : reader.uint32();
    if (PRIMITIVES[field.type] && PRIMITIVES[field.type][0] === 1 && field.type !== 'bool') {
      return reader.bytesOf(field.type, count);
    }
    if (count > reader.bytes.byteLength) throw new Error('CDR: array of ' + count + ' elements');
    const out = new Array(count);
    for (let i = 0; i < count; ++i) out[i] = readValue(reader, types, field.type);
    return out;
  }

  // A decoder for one advertised channel: bytes (Uint8Array, with the encapsulation header) ->
  // plain object with the .msg field names.
  function makeDecoder(schemaText, schemaName) {
    const parsed = parseRos2msg(schemaText, schemaName);
    return function decode(bytes) {
      return readValue(new CdrReader(bytes), parsed.types, parsed.root);
    };
  }

  const api = { parseRos2msg: parseRos2msg, makeDecoder: makeDecoder, CdrReader: CdrReader };
  if (typeof module !== 'undefined' && module.exports) module.exports = api;
  else root.SemapCdr = api;
})(typeof window !== 'undefined' ? window : globalThis);
