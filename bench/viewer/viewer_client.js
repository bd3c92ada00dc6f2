// The node client of bench/viewer/viewer_bench.sh (@foxglove/ws-protocol over ws, decoding with
// @foxglove/rosmsg + @foxglove/rosmsg2-serialization from the advertised schema; NODE_PATH from
// scripts/test-tools). Three modes, each printing one JSON line:
//
//   node viewer_client.js read  --url ws://.. --seconds S
//       subscribes to every channel and reads until S s or SIGTERM; decodes the map clouds and
//       the health reports (the others are only counted); prints messages and bytes per
//       channel, the newest map cloud's point count, the last health report's mapping and
//       perception latencies, and this client's own CPU
//   node viewer_client.js watch --url ws://.. --points N --max-seconds S
//       subscribes to /semap/map_cloud only and prints its point count as it grows; exits 0 once
//       a cloud has at least N points, 1 after S s
//   node viewer_client.js join  --url ws://.. --times K [--pause P]
//       K times: a new client connects, subscribes to /semap/map_cloud (latched) and times the
//       whole cloud message from its subscribe; prints each try and closes the connection
'use strict';
const { FoxgloveClient } = require('@foxglove/ws-protocol');
const { WebSocket } = require('ws');
const rosmsg = require('@foxglove/rosmsg');
const { MessageReader } = require('@foxglove/rosmsg2-serialization');

const mode = process.argv[2];
const a = {};
for (let i = 3; i < process.argv.length; i += 2) a[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
const url = a.url;
const sleep = (s) => new Promise((r) => setTimeout(r, s * 1000));
const topicIs = (topic, suffix) => ('/' + topic.replace(/^\/+/, '')).endsWith(suffix);
const json = (v) => JSON.stringify(v, (k, x) => (typeof x === 'bigint' ? Number(x) : x));
const die = (m) => {
  console.error('viewer_client: ' + m);
  process.exit(1);
};

// A FoxgloveClient, resolved with its channels once the server's advertise came.
function connect() {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const channels = new Map();
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error('no advertise from ' + url + ' in 10 s')), 10000);
    client.on('error', (e) => reject(e));
    client.on('advertise', (list) => {
      list.forEach((c) => channels.set(c.id, c));
      clearTimeout(timer);
      resolve({ ws, client, channels });
    });
  });
}
const decoder = (channel) => {
  const reader = new MessageReader(rosmsg.parse(channel.schema, { ros2: true }));
  return (data) => reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
};
const cloudChannel = (channels) => {
  const c = [...channels.values()].find((ch) => topicIs(ch.topic, '/semap/map_cloud'));
  if (!c) die('no /semap/map_cloud channel advertised');
  return c;
};

async function read() {
  const seconds = Number(a.seconds || 0);
  const cpu0 = process.cpuUsage();
  const t0 = performance.now();
  await sleep(0.3); // more advertise messages
  const { client, channels } = await connect();
  await sleep(0.3);
  const subs = new Map();
  for (const channel of channels.values()) {
    const decode = topicIs(channel.topic, '/semap/map_cloud') || topicIs(channel.topic, '/semap/health') ? decoder(channel) : null;
    subs.set(client.subscribe(channel.id), { channel, decode, messages: 0, bytes: 0 });
  }
  let cloudPoints = 0, health = null;
  client.on('message', ({ subscriptionId, data }) => {
    const s = subs.get(subscriptionId);
    if (!s) return;
    s.messages++;
    s.bytes += data.byteLength;
    if (!s.decode) return;
    const msg = s.decode(data);
    if (topicIs(s.channel.topic, '/semap/map_cloud')) cloudPoints = msg.width * msg.height;
    else health = msg;
  });
  const finish = () => {
    const stage = (name) => health && health.stages.find((st) => st.name === name);
    const lat = (name) => stage(name) ? [stage(name).latency_p50_ms, stage(name).latency_p99_ms].map((x) => Math.round(x * 10) / 10) : null;
    const cpu = process.cpuUsage(cpu0);
    const wall = (performance.now() - t0) / 1000;
    const channelsOut = {};
    let messages = 0, bytes = 0;
    for (const s of subs.values()) {
      channelsOut[s.channel.topic] = [s.messages, s.bytes];
      messages += s.messages;
      bytes += s.bytes;
    }
    const me = health && (health.viewers || [])[0];
    console.log(json({
      mode: 'read', seconds: Math.round(wall * 10) / 10, channels: subs.size, messages, megabytes: Math.round(bytes / 1e4) / 100,
      map_cloud_points: cloudPoints, health_mapping_p50_p99_ms: lat('mapping'), health_perception_p50_p99_ms: lat('perception'),
      server_dropped: me ? Number(me.messages_dropped) : null,
      client_cpu_cores: Math.round(((cpu.user + cpu.system) / 1e6 / wall) * 1000) / 1000, per_channel: channelsOut,
    }));
    process.exit(0);
  };
  process.on('SIGTERM', finish);
  // The robot closing the connection ends the run too.
  client.on('close', finish);
  if (seconds > 0) setTimeout(finish, seconds * 1000);
}

async function watch() {
  const want = Number(a.points || 100000);
  const maxS = Number(a['max-seconds'] || 300);
  const t0 = performance.now();
  const { client, channels } = await connect();
  const channel = cloudChannel(channels);
  const decode = decoder(channel);
  const id = client.subscribe(channel.id);
  client.on('message', ({ subscriptionId, data }) => {
    if (subscriptionId !== id) return;
    const msg = decode(data);
    const points = msg.width * msg.height;
    const t = (performance.now() - t0) / 1000;
    console.log(json({ mode: 'watch', t_s: Math.round(t), map_cloud_points: points, megabytes: Math.round(data.byteLength / 1e4) / 100 }));
    if (points >= want) process.exit(0);
  });
  client.on('close', () => die('the robot closed the connection before the map had ' + want + ' points'));
  setTimeout(() => die('the map did not reach ' + want + ' points in ' + maxS + ' s'), maxS * 1000);
}

async function join() {
  const times = Number(a.times || 5);
  const pause = Number(a.pause || 1);
  for (let i = 1; i <= times; ++i) {
    const tConnect = performance.now();
    const { ws, client, channels } = await connect();
    const tAdvertised = performance.now();
    const channel = cloudChannel(channels);
    const decode = decoder(channel);
    const result = await new Promise((resolve, reject) => {
      const timer = setTimeout(() => reject(new Error('no map cloud 10 s after subscribing')), 10000);
      let tSub = 0;
      let id = -1;
      client.on('message', ({ subscriptionId, data }) => {
        if (subscriptionId !== id) return;
        const tGot = performance.now(); // the whole message is here (ws hands over whole messages)
        const msg = decode(data);
        const tDecoded = performance.now();
        clearTimeout(timer);
        resolve({
          mode: 'join', try: i, map_cloud_points: msg.width * msg.height, megabytes: Math.round(data.byteLength / 1e4) / 100,
          connect_to_advertise_ms: Math.round((tAdvertised - tConnect) * 10) / 10,
          subscribe_to_message_ms: Math.round((tGot - tSub) * 10) / 10,
          decode_ms: Math.round((tDecoded - tGot) * 10) / 10,
        });
      });
      tSub = performance.now();
      id = client.subscribe(channel.id);
    });
    console.log(json(result));
    ws.close();
    await sleep(pause);
  }
  process.exit(0);
}

({ read, watch, join })[mode]
  ? ({ read, watch, join })[mode]().catch((e) => die(e.stack || e.message))
  : die('mode: read | watch | join');
