// @foxglove/ws-protocol's FoxgloveClient against a running semap-onboard (viewer_test.sh starts
// it): subscribes to every channel, decodes every message with @foxglove/rosmsg +
// @foxglove/rosmsg2-serialization from the advertised schema (and with the built-in page's
// decoder, which must agree), checks the costmap's size, the JPEGs, the health report; a
// second client subscribes to everything and then stops reading its socket: the robot's frame
// rate and latency (health, BASELINE s before the stall against STALL s of it, once mapping
// runs) must not change and that client's drops must be counted. Writes the
// odometry it received (odometry.csv) for the truth check after the robot exits (truth.js).
//
//   node ws_client_test.js --url ws://127.0.0.1:PORT/ --baseline 6 --stall 10 --max-seconds 60
//        --costmap 200x200 --costmap-resolution 0.2 --out DIR
'use strict';
const fs = require('fs');
const path = require('path');
const lib = require('./lib.js');
const { check, fail, log, topicIs } = lib;

const a = lib.args();
const baselineS = Number(a.baseline || 6);
const stallS = Number(a.stall || 10);
const maxSeconds = Number(a['max-seconds'] || 60);
const out = a.out || '.';
const [costmapW, costmapH] = (a.costmap || '0x0').split('x').map(Number);
const costmapRes = Number(a['costmap-resolution'] || 0);

// What must arrive, by topic suffix (a channel advertised beyond these is subscribed and
// decoded too).
const REQUIRED = ['/semap/odometry', '/semap/gnss', '/tf', '/tf_static', '/semap/costmap',
  '/semap/map_cloud', '/semap/map_cloud_updates', '/semap/map_info', '/semap/health',
  '/semap/camera/image/compressed', '/semap/segmentation/overlay/compressed'];
const LOCAL_NS_ROS = () => BigInt(Math.round((performance.timeOrigin + performance.now()) * 1e6));

async function main() {
  const t0 = performance.now();
  const now = () => (performance.now() - t0) / 1000;
  const { client, channels, info } = await lib.connect(a.url);
  log('server "' + (info && info.name) + '", ' + channels.size + ' channels: ' +
    [...channels.values()].map((c) => c.topic + ' (' + c.schemaName + ')').join(', '));
  for (const t of REQUIRED) {
    check([...channels.values()].some((c) => topicIs(c.topic, t)), 'no channel advertised for ' + t);
  }

  // The robot's clock offset (ROS time = CLOCK_MONOTONIC + offset), to put the odometry's ROS
  // stamps on the truth's monotonic clock: process.hrtime is CLOCK_MONOTONIC.
  const offsets = [];
  for (let i = 0; i < 9; ++i) offsets.push(LOCAL_NS_ROS() - process.hrtime.bigint());
  offsets.sort((x, y) => (x < y ? -1 : 1));
  const rosToMono = offsets[4];

  const subs = new Map(); // subscription id -> {channel, ref, page, count, bytes}
  for (const channel of channels.values()) {
    const id = client.subscribe(channel.id);
    subs.set(id, { channel, ref: lib.referenceDecoder(channel), page: lib.pageDecoder(channel), count: 0, compared: 0 });
  }

  const odometry = ['mono_s,x,y,z'];
  const health = []; // {t, msg}
  const images = { camera: [], overlay: [] };
  let costmap = null;
  let costmapUpdates = 0;
  let clouds = 0, cloudPoints = 0;
  let mapInfo = null;
  let odomDuringStall = 0;
  let stalled = null;
  let mappingSince = null;

  client.on('message', ({ subscriptionId, data }) => {
    const sub = subs.get(subscriptionId);
    if (!sub) return;
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    const topic = sub.channel.topic;
    let msg;
    try {
      msg = sub.ref(bytes);
    } catch (e) {
      fail(topic + ' message ' + sub.count + ' does not decode with rosmsg2-serialization: ' + e.message);
    }
    sub.count++;
    // The page's decoder on every message of the small channels, every 5th of the big ones.
    if (bytes.byteLength < 65536 || sub.count % 5 === 1) {
      let mine;
      try {
        mine = sub.page(bytes);
      } catch (e) {
        fail(topic + ': the page\'s decoder fails: ' + e.message);
      }
      const diff = lib.sameMessage(msg, mine, topic);
      check(!diff, 'the page\'s decoder disagrees with rosmsg2-serialization: ' + diff);
      sub.compared++;
    }
    const t = now();
    if (topicIs(topic, '/semap/odometry')) {
      const p = msg.pose.pose.position;
      check([p.x, p.y, p.z].every(Number.isFinite), 'odometry not finite: ' + JSON.stringify(p));
      const ros = BigInt(msg.header.stamp.sec) * 1000000000n + BigInt(msg.header.stamp.nanosec);
      const mono = Number(ros - rosToMono) / 1e9;
      odometry.push(mono.toFixed(6) + ',' + p.x + ',' + p.y + ',' + p.z);
      if (stalled && t > stalled.at + 2) odomDuringStall++;
    } else if (topicIs(topic, '/semap/gnss')) {
      check(Math.abs(msg.latitude) <= 90 && Math.abs(msg.longitude) <= 180 && msg.status.status >= 0,
        'gnss fix out of range: ' + msg.latitude + ', ' + msg.longitude + ' status ' + msg.status.status);
      check(msg.header.frame_id === 'gnss', 'gnss frame_id "' + msg.header.frame_id + '"');
    } else if (topicIs(topic, '/semap/health')) {
      health.push({ t, msg });
      // The baseline starts once perception and mapping run (the filter's heading settles first).
      const running = ['perception', 'mapping'].every((n) => (msg.stages.find((s) => s.name === n) || {}).rate_hz > 0);
      if (running && mappingSince === null) mappingSince = t;
    } else if (topicIs(topic, '/semap/costmap')) {
      costmap = msg;
    } else if (topicIs(topic, '/semap/costmap_updates')) {
      costmapUpdates++;
      check(msg.data.length === msg.width * msg.height, 'costmap update: ' + msg.data.length + ' cells for ' + msg.width + 'x' + msg.height);
    } else if (topicIs(topic, '/semap/map_cloud') || topicIs(topic, '/semap/map_cloud_updates')) {
      clouds++;
      cloudPoints += msg.width * msg.height;
      check(msg.data.length === msg.width * msg.height * msg.point_step, topic + ': data length');
      check(['x', 'y', 'z'].every((n) => msg.fields.some((f) => f.name === n)), topic + ': no x, y, z fields');
    } else if (topicIs(topic, '/semap/map_info')) {
      mapInfo = msg;
    } else if (topicIs(topic, '/semap/camera/image/compressed') || topicIs(topic, '/semap/segmentation/overlay/compressed')) {
      const kind = topicIs(topic, '/semap/camera/image/compressed') ? 'camera' : 'overlay';
      const size = lib.jpegSize(msg.data);
      check(/jpe?g/.test(msg.format), topic + ': format "' + msg.format + '"');
      check(size && size.width > 0 && size.height > 0, topic + ': message ' + sub.count + ' is not a whole JPEG (' + msg.data.length + ' bytes)');
      images[kind].push(size);
      if (images[kind].length === 1) fs.writeFileSync(path.join(out, kind + '.jpg'), msg.data);
    }
  });

  // Wait for mapping to run, then BASELINE s of health reports, then the stalled client:
  // subscribes to everything, reads for a second, then pauses its socket (the kernel's receive
  // buffer fills, then the server's send side); STALL s of it.
  const sleep = (s) => new Promise((r) => setTimeout(r, s * 1000));
  while (mappingSince === null || now() < mappingSince + 1 + baselineS - 1) {
    check(now() < maxSeconds - stallS - 3, 'perception and mapping not running after ' + now().toFixed(0) + ' s');
    await sleep(0.2);
  }
  const s = await lib.connect(a.url);
  for (const channel of s.channels.values()) s.client.subscribe(channel.id);
  await sleep(1);
  s.ws._socket.pause();
  stalled = { port: s.ws._socket.localPort, at: now(), ws: s.ws };
  log('mapping runs since ' + mappingSince.toFixed(1) + ' s; the client on port ' + stalled.port +
    ' stopped reading at ' + stalled.at.toFixed(1) + ' s');
  await sleep(stallS);
  const seconds = now();
  fs.writeFileSync(path.join(out, 'odometry.csv'), odometry.join('\n') + '\n');

  // Every channel delivered and decoded.
  for (const sub of subs.values()) {
    log(sub.channel.topic + ': ' + sub.count + ' messages, ' + sub.compared + ' compared with the page\'s decoder');
  }
  for (const t of REQUIRED) {
    const n = [...subs.values()].filter((s) => topicIs(s.channel.topic, t)).reduce((x, s) => x + s.count, 0);
    check(n > 0, 'no message on ' + t);
  }
  check(odometry.length > 100, 'only ' + (odometry.length - 1) + ' odometry messages');

  // Costmap: the configured size.
  check(costmap, 'no costmap');
  log('costmap ' + costmap.info.width + 'x' + costmap.info.height + ' at ' + costmap.info.resolution.toFixed(3) +
    ' m, ' + costmapUpdates + ' updates');
  if (costmapW) {
    check(costmap.info.width === costmapW && costmap.info.height === costmapH,
      'costmap ' + costmap.info.width + 'x' + costmap.info.height + ', configured ' + costmapW + 'x' + costmapH);
  }
  if (costmapRes) check(Math.abs(costmap.info.resolution - costmapRes) < 1e-5, 'costmap resolution ' + costmap.info.resolution);
  check(costmap.data.length === costmap.info.width * costmap.info.height, 'costmap data length');
  check(costmap.data.some((c) => c >= 0), 'costmap has no known cell');

  // The map.
  check(mapInfo && mapInfo.class_names.length === mapInfo.class_colors.length && mapInfo.class_names.length > 1,
    'map_info: ' + JSON.stringify(mapInfo && mapInfo.class_names));
  check(cloudPoints > 0, 'map clouds carried no point');
  log(clouds + ' map clouds, ' + cloudPoints + ' points; classes ' + mapInfo.class_names.join(' '));

  // Images.
  for (const kind of ['camera', 'overlay']) {
    const list = images[kind];
    check(list.length >= 3, 'only ' + list.length + ' ' + kind + ' images');
    log(kind + ': ' + list.length + ' JPEGs, ' + list[0].width + 'x' + list[0].height);
  }

  // Health, and the stalled client.
  check(health.length >= seconds / 2, 'only ' + health.length + ' health reports in ' + seconds.toFixed(0) + ' s');
  const stage = (m, name) => m.stages.find((s) => s.name === name);
  for (const h of health) {
    for (const name of ['estimation', 'perception', 'mapping']) check(stage(h.msg, name), 'health without stage ' + name);
  }
  check(stalled, 'the stalled client never connected');
  // A report covers the second before it: the first one after mapping started is partial.
  const before = health.filter((h) => h.t >= mappingSince + 1.5 && h.t < stalled.at - 1);
  const during = health.filter((h) => h.t >= stalled.at + 2);
  check(before.length >= 3 && during.length >= 5, 'health reports: ' + before.length + ' before the stall, ' + during.length + ' during');
  const mean = (list, f) => list.reduce((s, h) => s + f(h), 0) / list.length;
  const median = (list, f) => {
    const v = list.map(f).sort((x, y) => x - y);
    return v[Math.floor(v.length / 2)];
  };
  const figures = (list) => ({
    perception_hz: mean(list, (h) => stage(h.msg, 'perception').rate_hz),
    mapping_hz: mean(list, (h) => stage(h.msg, 'mapping').rate_hz),
    perception_p50_ms: median(list, (h) => stage(h.msg, 'perception').latency_p50_ms),
    mapping_p50_ms: median(list, (h) => stage(h.msg, 'mapping').latency_p50_ms),
  });
  const base = figures(before), stall = figures(during);
  log('before the stall ' + JSON.stringify(base) + ', during it ' + JSON.stringify(stall));
  const last = health[health.length - 1].msg;
  const viewers = last.viewers || [];
  log('viewer clients in the last health report: ' + JSON.stringify(viewers, (k, v) => (typeof v === 'bigint' ? Number(v) : v)));
  const stalledEntry = viewers.find((v) => v.address.endsWith(':' + stalled.port));
  check(stalledEntry, 'the health report has no viewer client on port ' + stalled.port);
  check(Number(stalledEntry.messages_dropped) > 0, 'the stalled client has no drops counted: ' + JSON.stringify(stalledEntry, (k, v) => (typeof v === 'bigint' ? Number(v) : v)));
  check(viewers.length >= 2, 'the health report lists ' + viewers.length + ' viewer clients, 2 are connected');
  for (const key of ['perception_hz', 'mapping_hz']) {
    check(stall[key] >= 0.6 * base[key] - 1, key + ' fell from ' + base[key].toFixed(2) + ' to ' + stall[key].toFixed(2) + ' with a stalled client');
  }
  for (const key of ['perception_p50_ms', 'mapping_p50_ms']) {
    check(stall[key] <= 2 * base[key] + 50, key + ' rose from ' + base[key].toFixed(1) + ' to ' + stall[key].toFixed(1) + ' ms with a stalled client');
  }
  // The reading client kept getting odometry while the other one stalled.
  const odomRate = odomDuringStall / (seconds - stalled.at - 2);
  log('odometry to the reading client during the stall: ' + odomRate.toFixed(1) + ' Hz');
  check(odomRate > 5, 'the reading client got odometry at ' + odomRate.toFixed(1) + ' Hz during the stall');

  fs.writeFileSync(path.join(out, 'ws_client.json'), JSON.stringify({
    channels: [...subs.values()].map((s) => ({ topic: s.channel.topic, schema: s.channel.schemaName, messages: s.count })),
    before_stall: base, during_stall: stall, stalled_client: stalledEntry,
    costmap: { width: costmap.info.width, height: costmap.info.height, resolution: costmap.info.resolution },
  }, (k, v) => (typeof v === 'bigint' ? Number(v) : v), 2));
  stalled.ws.terminate();
  client.close();
  log('PASS (the odometry against the truth is checked after the robot exits)');
  process.exit(0);
}

main().catch((e) => fail(e.stack || e.message));
