// semap viewer: connects to semap-onboard's Foxglove WebSocket server (subprotocol
// foxglove.websocket.v1, the port this page came from), subscribes to the channels below and
// draws them. Messages are CDR, decoded from the advertised ros2msg schema (cdr.js).
//
// window.semapViewer is the page's state, for tests and the browser console:
//   connected, messages, byTopic{topic: count}, pose{x, y, yaw}, trailLength, cells, classes,
//   costmap{width, height, resolution}, images{camera, overlay}, health, errors[].
(function () {
  'use strict';

  // Topics by suffix: a robot's namespace comes first (/robot1/semap/odometry).
  const TOPICS = {
    mapCloud: '/semap/map_cloud',
    mapCloudUpdates: '/semap/map_cloud_updates',
    mapInfo: '/semap/map_info',
    costmap: '/semap/costmap',
    costmapUpdates: '/semap/costmap_updates',
    odometry: '/semap/odometry',
    camera: '/semap/camera/image/compressed',
    overlay: '/semap/segmentation/overlay/compressed',
    health: '/semap/health',
  };
  const REMOVED_CLASS = 0xffff; // a map_cloud_updates cell that is no longer occupied
  const TRAIL_MAX = 5000;
  const $ = (id) => document.getElementById(id);

  const state = {
    connected: false,
    messages: 0,
    byTopic: {},
    pose: null,
    trailLength: 0,
    cells: 0,
    classes: [],
    costmap: null,
    images: { camera: 0, overlay: 0 },
    health: null,
    errors: [],
  };
  window.semapViewer = state;

  function topicKind(topic) {
    const t = '/' + topic.replace(/^\/+/, '');
    for (const [kind, suffix] of Object.entries(TOPICS)) if (t.endsWith(suffix)) return kind;
    return null;
  }
  function noteError(what, err) {
    const text = what + ': ' + (err && err.message ? err.message : String(err));
    if (state.errors.length < 50) state.errors.push(text);
    console.warn(text);
  }

  // ---- the WebSocket --------------------------------------------------------------------------
  let ws = null;
  const subscriptions = new Map(); // subscription id -> {channel, kind, decode}
  let nextSubscription = 1;

  function socketUrl() {
    const params = new URLSearchParams(location.search);
    const url = new URL(params.get('ws') || (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/');
    if (params.get('token')) url.searchParams.set('token', params.get('token'));
    return url.toString();
  }

  function connect() {
    try {
      ws = new WebSocket(socketUrl(), ['foxglove.websocket.v1']);
    } catch (err) {
      noteError('websocket', err);
      setTimeout(connect, 2000);
      return;
    }
    ws.binaryType = 'arraybuffer';
    ws.onopen = () => setStatus(true);
    ws.onclose = () => {
      setStatus(false);
      subscriptions.clear();
      setTimeout(connect, 2000);
    };
    ws.onerror = () => setStatus(false);
    ws.onmessage = (event) => {
      try {
        if (typeof event.data === 'string') onJson(JSON.parse(event.data));
        else onBinary(new Uint8Array(event.data));
      } catch (err) {
        noteError('message', err);
      }
    };
  }

  function setStatus(on) {
    state.connected = on;
    $('status').textContent = on ? 'live' : 'disconnected';
    $('status').className = 'status ' + (on ? 'on' : 'off');
  }

  function onJson(msg) {
    if (msg.op === 'serverInfo') {
      $('robot').textContent = msg.name || '';
    } else if (msg.op === 'advertise') {
      const wanted = [];
      for (const channel of msg.channels) {
        const kind = topicKind(channel.topic);
        if (!kind || channel.encoding !== 'cdr') continue;
        if (channel.schemaEncoding && channel.schemaEncoding !== 'ros2msg') continue;
        let decode;
        try {
          decode = SemapCdr.makeDecoder(channel.schema, channel.schemaName);
        } catch (err) {
          noteError(channel.topic + ' schema', err);
          continue;
        }
        const id = nextSubscription++;
        subscriptions.set(id, { channel: channel, kind: kind, decode: decode });
        wanted.push({ id: id, channelId: channel.id });
      }
      if (wanted.length) ws.send(JSON.stringify({ op: 'subscribe', subscriptions: wanted }));
    } else if (msg.op === 'unadvertise') {
      const gone = new Set(msg.channelIds);
      for (const [id, sub] of subscriptions) if (gone.has(sub.channel.id)) subscriptions.delete(id);
    } else if (msg.op === 'status' && msg.level >= 1) {
      noteError('server', msg.message);
    }
  }

  function onBinary(bytes) {
    if (bytes[0] !== 0x01 || bytes.length < 13) return; // only Message Data
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const sub = subscriptions.get(view.getUint32(1, true));
    if (!sub) return;
    const topic = sub.channel.topic;
    state.messages++;
    state.byTopic[topic] = (state.byTopic[topic] || 0) + 1;
    let msg;
    try {
      msg = sub.decode(bytes.subarray(13));
    } catch (err) {
      noteError(topic, err);
      return;
    }
    HANDLERS[sub.kind](msg);
  }

  const HANDLERS = {
    mapCloud: (m) => mapLayer.cloud(m, true),
    mapCloudUpdates: (m) => mapLayer.cloud(m, false),
    mapInfo: (m) => mapLayer.info(m),
    costmap: (m) => costmapLayer.grid(m),
    costmapUpdates: (m) => costmapLayer.update(m),
    odometry: onOdometry,
    camera: (m) => images.show('camera', m),
    overlay: (m) => images.show('overlay', m),
    health: onHealth,
  };

  // ---- the map: occupied cells from PointCloud2, drawn top-down in class colours -------------
  const mapLayer = {
    resolution: 0.2,
    colors: [], // 0xRRGGBB per class, from MapInfo
    cells: new Map(), // "ix,iy,iz" -> cls * 2^24 + rgb
    canvas: document.createElement('canvas'),
    origin: null, // [ix, iy] of the raster's first pixel
    stale: true,

    info(m) {
      if (m.resolution > 0) this.resolution = m.resolution;
      this.colors = Array.from(m.class_colors);
      state.classes = m.class_names.map((name, i) => ({ name: name, color: this.colors[i] }));
      showLegend(state.classes);
      this.stale = true;
      requestDraw();
    },

    cloud(m, whole) {
      const fields = {};
      for (const f of m.fields) fields[f.name] = f;
      if (!fields.x || !fields.y || !fields.z) throw new Error('PointCloud2 without x, y, z');
      const cls = fields.class || fields.label;
      const data = m.data;
      const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
      const little = !m.is_bigendian;
      const n = m.width * m.height;
      const step = m.point_step;
      const res = this.resolution;
      if (whole) this.cells.clear();
      for (let i = 0; i < n && (i + 1) * step <= data.byteLength; ++i) {
        const o = i * step;
        const x = view.getFloat32(o + fields.x.offset, little);
        const y = view.getFloat32(o + fields.y.offset, little);
        const z = view.getFloat32(o + fields.z.offset, little);
        const c = cls ? readNumber(view, o + cls.offset, cls.datatype, little) : 0;
        const rgb = fields.rgb ? view.getUint32(o + fields.rgb.offset, little) & 0xffffff : 0x808080;
        const key = Math.floor(x / res) + ',' + Math.floor(y / res) + ',' + Math.floor(z / res);
        if (c === REMOVED_CLASS) this.cells.delete(key);
        else this.cells.set(key, c * 0x1000000 + rgb);
      }
      state.cells = this.cells.size;
      this.stale = true;
      requestDraw();
    },

    colorOf(packed) {
      const c = Math.floor(packed / 0x1000000);
      return c < this.colors.length ? this.colors[c] & 0xffffff : packed % 0x1000000;
    },

    // One pixel per map column, the column's highest occupied cell's colour.
    raster() {
      if (!this.stale) return;
      this.stale = false;
      let minX = Infinity, minY = Infinity, maxX = -Infinity, maxY = -Infinity;
      const parsed = [];
      for (const [key, packed] of this.cells) {
        const [ix, iy, iz] = key.split(',').map(Number);
        parsed.push(ix, iy, iz, packed);
        if (ix < minX) minX = ix;
        if (ix > maxX) maxX = ix;
        if (iy < minY) minY = iy;
        if (iy > maxY) maxY = iy;
      }
      if (!parsed.length) {
        this.origin = null;
        return;
      }
      const w = maxX - minX + 1, h = maxY - minY + 1;
      if (w * h > 16e6) return noteError('map', 'too large to draw: ' + w + ' x ' + h + ' cells');
      this.canvas.width = w;
      this.canvas.height = h;
      const ctx = this.canvas.getContext('2d');
      const image = ctx.createImageData(w, h);
      const top = new Int32Array(w * h).fill(-2147483648);
      for (let i = 0; i < parsed.length; i += 4) {
        const col = parsed[i] - minX;
        const row = h - 1 - (parsed[i + 1] - minY); // image rows go down, y goes up
        const p = row * w + col;
        if (parsed[i + 2] < top[p]) continue;
        top[p] = parsed[i + 2];
        const rgb = this.colorOf(parsed[i + 3]);
        image.data.set([rgb >> 16, (rgb >> 8) & 255, rgb & 255, 255], p * 4);
      }
      ctx.putImageData(image, 0, 0);
      this.origin = [minX, minY];
      this.bounds = [minX * this.resolution, minY * this.resolution, (maxX + 1) * this.resolution, (maxY + 1) * this.resolution];
    },
  };

  function readNumber(view, offset, datatype, little) {
    switch (datatype) {
      case 1: return view.getInt8(offset);
      case 2: return view.getUint8(offset);
      case 3: return view.getInt16(offset, little);
      case 4: return view.getUint16(offset, little);
      case 5: return view.getInt32(offset, little);
      case 6: return view.getUint32(offset, little);
      case 7: return view.getFloat32(offset, little);
      case 8: return view.getFloat64(offset, little);
    }
    return 0;
  }

  function hex(rgb) {
    return '#' + (rgb & 0xffffff).toString(16).padStart(6, '0');
  }

  function showLegend(classes) {
    const legend = $('legend');
    legend.textContent = '';
    classes.forEach((c, i) => {
      if (i === 0 && c.name === 'free') return; // never an occupied cell
      const li = document.createElement('li');
      const swatch = document.createElement('span');
      swatch.className = 'swatch';
      swatch.style.background = hex(c.color);
      li.append(swatch, document.createTextNode(c.name));
      legend.append(li);
    });
  }

  // ---- the costmap: OccupancyGrid + OccupancyGridUpdate ---------------------------------------
  const costmapLayer = {
    current: null, // {width, height, resolution, x, y, yaw, data: Int8Array}
    canvas: document.createElement('canvas'),
    stale: false,

    grid(m) {
      const info = m.info;
      this.current = {
        width: info.width,
        height: info.height,
        resolution: info.resolution,
        x: info.origin.position.x,
        y: info.origin.position.y,
        yaw: yawOf(info.origin.orientation),
        data: new Int8Array(m.data), // a copy: updates write into it
      };
      state.costmap = { width: info.width, height: info.height, resolution: info.resolution };
      this.stale = true;
      requestDraw();
    },

    update(m) {
      const g = this.current;
      if (!g || m.x < 0 || m.y < 0 || m.x + m.width > g.width || m.y + m.height > g.height) return;
      for (let r = 0; r < m.height; ++r) {
        g.data.set(m.data.subarray(r * m.width, (r + 1) * m.width), (m.y + r) * g.width + m.x);
      }
      this.stale = true;
      requestDraw();
    },

    raster() {
      if (!this.stale || !this.current) return;
      this.stale = false;
      const g = this.current;
      this.canvas.width = g.width;
      this.canvas.height = g.height;
      const ctx = this.canvas.getContext('2d');
      const image = ctx.createImageData(g.width, g.height);
      for (let row = 0; row < g.height; ++row) {
        for (let col = 0; col < g.width; ++col) {
          const cost = g.data[row * g.width + col];
          if (cost < 0) continue; // unknown: transparent
          const p = ((g.height - 1 - row) * g.width + col) * 4;
          const t = Math.min(cost, 100) / 100;
          if (cost === 0) image.data.set([120, 200, 255, 40], p);
          else image.data.set([255, 210 * (1 - t), 0, 70 + 110 * t], p);
        }
      }
      ctx.putImageData(image, 0, 0);
    },
  };

  function yawOf(q) {
    return Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
  }

  // ---- pose and trail ---------------------------------------------------------------------------
  const trail = [];
  function onOdometry(m) {
    const p = m.pose.pose.position;
    const pose = { x: p.x, y: p.y, z: p.z, yaw: yawOf(m.pose.pose.orientation), frame: m.header.frame_id };
    state.pose = pose;
    const last = trail[trail.length - 1];
    if (!last || Math.hypot(last[0] - pose.x, last[1] - pose.y) > 0.05) {
      trail.push([pose.x, pose.y]);
      if (trail.length > TRAIL_MAX) trail.splice(0, trail.length - TRAIL_MAX);
    }
    state.trailLength = trail.length;
    requestDraw();
  }

  // ---- camera and segmentation overlay (JPEG) ---------------------------------------------------
  const images = {
    busy: {}, // kind -> true while an image decodes
    next: {}, // kind -> the newest image waiting for it

    show(kind, m) {
      state.images[kind]++;
      const blob = new Blob([m.data], { type: m.format && m.format.includes('png') ? 'image/png' : 'image/jpeg' });
      if (this.busy[kind]) {
        this.next[kind] = blob; // the browser is slower than the robot: show the newest only
        return;
      }
      this.load(kind, blob);
    },

    load(kind, blob) {
      this.busy[kind] = true;
      const img = $(kind);
      const url = URL.createObjectURL(blob);
      const previous = img.dataset.url;
      img.onload = img.onerror = () => {
        if (previous) URL.revokeObjectURL(previous);
        this.busy[kind] = false;
        if (kind === 'camera') $('image-info').textContent = img.naturalWidth + ' x ' + img.naturalHeight;
        const waiting = this.next[kind];
        this.next[kind] = null;
        if (waiting) this.load(kind, waiting);
      };
      img.dataset.url = url;
      img.src = url;
    },
  };
  $('overlay-opacity').addEventListener('input', (e) => {
    $('overlay').style.opacity = e.target.value / 100;
  });

  // ---- health ---------------------------------------------------------------------------------
  let healthAt = 0;
  function onHealth(m) {
    state.health = m;
    healthAt = performance.now();
    const cell = (text, cls) => {
      const td = document.createElement('td');
      td.textContent = text;
      if (cls) td.className = cls;
      return td;
    };
    const rows = (id, items, columns) => {
      const body = $(id).querySelector('tbody');
      body.textContent = '';
      for (const item of items) {
        const tr = document.createElement('tr');
        for (const c of columns(item)) tr.append(Array.isArray(c) ? cell(c[0], c[1]) : cell(c));
        body.append(tr);
      }
    };
    const fixed = (v, d) => Number(v).toFixed(d);
    rows('stages', m.stages, (s) => [s.name, fixed(s.rate_hz, 1), s.queue_depth,
      [s.drops, s.drops > 0 ? 'warn' : ''], fixed(s.latency_p50_ms, 1), fixed(s.latency_p99_ms, 1)]);
    rows('drivers', m.drivers, (d) => [d.name, d.frames, [d.bad_frames, d.bad_frames > 0 ? 'warn' : ''],
      [d.dropped, d.dropped > 0 ? 'warn' : ''], d.reconnects]);
    rows('viewers', m.viewers || [], (v) => [v.address, v.messages_sent,
      [v.messages_dropped, v.messages_dropped > 0 ? 'warn' : ''], fixed(v.bytes_sent / 1048576, 1)]);
    $('writers').textContent = (m.writers || []).map((w) =>
      w.name + ': ' + w.writes + ' writes' + (w.failures ? ', ' + w.failures + ' failed' : '') +
      (w.failing ? ' (failing: ' + w.last_error + ')' : '')).join(' · ');
  }
  setInterval(() => {
    $('health-age').textContent = healthAt ? '(' + ((performance.now() - healthAt) / 1000).toFixed(0) + ' s ago)' : '';
  }, 1000);

  // ---- the view: world metres -> canvas pixels, auto-fit, pan and zoom ---------------------------
  const canvas = $('map');
  const view = { scale: 10, cx: 0, cy: 0, mode: 'fit' }; // pixels per metre, world centre; fit | follow | free
  let drawQueued = false;

  function requestDraw() {
    if (drawQueued) return;
    drawQueued = true;
    requestAnimationFrame(draw);
  }

  function contentBounds() {
    let b = mapLayer.bounds && mapLayer.origin ? mapLayer.bounds.slice() : null;
    const add = (x, y) => {
      if (!b) b = [x, y, x, y];
      b = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
    };
    for (const [x, y] of trail) add(x, y);
    return b;
  }

  function fitView() {
    const b = contentBounds();
    if (!b) return;
    const w = Math.max(b[2] - b[0], 10), h = Math.max(b[3] - b[1], 10);
    view.cx = (b[0] + b[2]) / 2;
    view.cy = (b[1] + b[3]) / 2;
    view.scale = 0.9 * Math.min(canvas.width / w, canvas.height / h);
  }

  function toScreen(x, y) {
    return [canvas.width / 2 + (x - view.cx) * view.scale, canvas.height / 2 - (y - view.cy) * view.scale];
  }
  function toWorld(px, py) {
    return [view.cx + (px - canvas.width / 2) / view.scale, view.cy - (py - canvas.height / 2) / view.scale];
  }

  function draw() {
    drawQueued = false;
    const ctx = canvas.getContext('2d');
    if (view.mode === 'fit') fitView();
    if (view.mode === 'follow' && state.pose) {
      view.cx = state.pose.x;
      view.cy = state.pose.y;
    }
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.imageSmoothingEnabled = false; // cells keep their class colours exactly
    const s = view.scale;
    const [ox, oy] = toScreen(0, 0);

    mapLayer.raster();
    if ($('layer-map').checked && mapLayer.origin) {
      const r = mapLayer.resolution;
      const [x0, y1] = toScreen(mapLayer.origin[0] * r, (mapLayer.origin[1] + mapLayer.canvas.height) * r);
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      ctx.drawImage(mapLayer.canvas, x0, y1, mapLayer.canvas.width * r * s, mapLayer.canvas.height * r * s);
    }

    // The costmap over the map, translucent: free cells tinted, costs from yellow to red.
    costmapLayer.raster();
    const g = costmapLayer.current;
    if ($('layer-costmap').checked && g) {
      ctx.setTransform(s, 0, 0, -s, ox, oy); // world metres, y up
      ctx.translate(g.x, g.y);
      ctx.rotate(g.yaw);
      ctx.scale(1, -1); // the image's first row is the grid's last
      ctx.drawImage(costmapLayer.canvas, 0, -g.height * g.resolution, g.width * g.resolution, g.height * g.resolution);
    }

    ctx.setTransform(1, 0, 0, 1, 0, 0);
    const px = window.devicePixelRatio || 1;
    if ($('layer-trail').checked && trail.length > 1) {
      ctx.strokeStyle = 'rgba(255, 200, 40, 0.9)';
      ctx.lineWidth = 2 * px;
      ctx.beginPath();
      trail.forEach(([x, y], i) => (i ? ctx.lineTo : ctx.moveTo).apply(ctx, toScreen(x, y)));
      ctx.stroke();
    }
    if (state.pose) {
      const [x, y] = toScreen(state.pose.x, state.pose.y);
      const size = 9 * px;
      ctx.translate(x, y);
      ctx.rotate(-state.pose.yaw);
      ctx.fillStyle = '#ff3b30';
      ctx.strokeStyle = '#fff';
      ctx.lineWidth = 1.5 * px;
      ctx.beginPath();
      ctx.moveTo(size * 1.4, 0);
      ctx.lineTo(-size, size * 0.8);
      ctx.lineTo(-size * 0.5, 0);
      ctx.lineTo(-size, -size * 0.8);
      ctx.closePath();
      ctx.fill();
      ctx.stroke();
      ctx.setTransform(1, 0, 0, 1, 0, 0);
    }
    drawScaleBar(ctx, px);
    const pose = state.pose ? 'x ' + state.pose.x.toFixed(1) + ' m, y ' + state.pose.y.toFixed(1) + ' m · ' : '';
    $('map-info').textContent = pose + state.cells + ' cells' +
      (g ? ' · costmap ' + g.width + ' x ' + g.height : '') + ' · ' + state.messages + ' messages';
  }

  function drawScaleBar(ctx, px) {
    const target = 120 * px / view.scale; // metres in ~120 CSS px
    const step = [1, 2, 5].map((m) => m * Math.pow(10, Math.floor(Math.log10(target))))
      .reduce((best, v) => (v <= target ? v : best), Math.pow(10, Math.floor(Math.log10(target))));
    const len = step * view.scale;
    const x = canvas.width - len - 12 * px, y = canvas.height - 12 * px;
    ctx.strokeStyle = '#d8dde3';
    ctx.lineWidth = 2 * px;
    ctx.beginPath();
    ctx.moveTo(x, y - 5 * px);
    ctx.lineTo(x, y);
    ctx.lineTo(x + len, y);
    ctx.lineTo(x + len, y - 5 * px);
    ctx.stroke();
    ctx.fillStyle = '#d8dde3';
    ctx.font = 11 * px + 'px system-ui, sans-serif';
    ctx.fillText(step + ' m', x, y - 7 * px);
  }

  function resize() {
    const r = canvas.getBoundingClientRect();
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(r.width * dpr)), h = Math.max(1, Math.round(r.height * dpr));
    if (canvas.width !== w || canvas.height !== h) {
      canvas.width = w;
      canvas.height = h;
      requestDraw();
    }
  }
  new ResizeObserver(resize).observe(canvas);

  function setMode(mode) {
    view.mode = mode;
    $('fit').classList.toggle('on', mode === 'fit');
    $('follow').classList.toggle('on', mode === 'follow');
    requestDraw();
  }
  $('fit').addEventListener('click', () => setMode('fit'));
  $('follow').addEventListener('click', () => setMode(view.mode === 'follow' ? 'free' : 'follow'));
  for (const id of ['layer-costmap', 'layer-map', 'layer-trail']) $(id).addEventListener('change', requestDraw);

  // Zoom about a canvas point (device pixels), keeping the world point under it in place.
  function zoomAt(px, py, factor) {
    const [wx, wy] = toWorld(px, py);
    view.scale = Math.min(Math.max(view.scale * factor, 0.05), 2000);
    const [nx, ny] = toWorld(px, py);
    view.cx += wx - nx;
    view.cy += wy - ny;
    if (view.mode === 'fit') setMode('free');
    requestDraw();
  }
  function canvasPoint(e) {
    const r = canvas.getBoundingClientRect();
    const dpr = canvas.width / r.width;
    return [(e.clientX - r.left) * dpr, (e.clientY - r.top) * dpr];
  }
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    const [x, y] = canvasPoint(e);
    zoomAt(x, y, Math.exp(-e.deltaY * (e.deltaMode === 1 ? 0.05 : 0.002)));
  }, { passive: false });

  // Drag with a mouse or one finger; pinch with two.
  const pointers = new Map();
  let pinch = null;
  canvas.addEventListener('pointerdown', (e) => {
    canvas.setPointerCapture(e.pointerId);
    pointers.set(e.pointerId, canvasPoint(e));
    pinch = null;
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!pointers.has(e.pointerId)) return;
    const before = pointers.get(e.pointerId);
    const now = canvasPoint(e);
    pointers.set(e.pointerId, now);
    if (pointers.size === 1) {
      view.cx -= (now[0] - before[0]) / view.scale;
      view.cy += (now[1] - before[1]) / view.scale;
      setMode('free');
    } else if (pointers.size === 2) {
      const [a, b] = [...pointers.values()];
      const distance = Math.hypot(a[0] - b[0], a[1] - b[1]);
      const mid = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2];
      if (pinch) {
        zoomAt(mid[0], mid[1], distance / Math.max(pinch.distance, 1));
        view.cx -= (mid[0] - pinch.mid[0]) / view.scale;
        view.cy += (mid[1] - pinch.mid[1]) / view.scale;
      }
      pinch = { distance: distance, mid: mid };
    }
    requestDraw();
  });
  const release = (e) => {
    pointers.delete(e.pointerId);
    pinch = null;
  };
  canvas.addEventListener('pointerup', release);
  canvas.addEventListener('pointercancel', release);

  setMode('fit');
  setStatus(false);
  connect();
})();
