// The live page of `avs view` (docs/view.md): connects back to the server it came from with
// the Foxglove WebSocket client, decodes the CDR messages with the advertised ros2msg
// schemas, and draws the depth map with the target's centroid, the pose and its error against
// the simulator's ground truth, the head angles and torques, the stage times and a 3-D view of
// the scene points with the model. Images and clouds are asked for at most max_rate_hz
// (default 15; ?max_rate_hz=N in the page URL), which the server applies per client.
// window.avsView holds counters for tests.
import {parse} from '@foxglove/rosmsg';
import {MessageReader} from '@foxglove/rosmsg2-serialization';
import {FoxgloveClient} from '@foxglove/ws-protocol';

import {cloudPoints, Scene3d} from './scene3d.js';
import {Series, TimePlot} from './timeplot.js';

const state = (window.avsView = {
  connected: false,
  depthFrames: 0,
  poseCount: 0,
  jointCount: 0,
  diagnosticsCount: 0,
  targetCount: 0,
  torqueCount: 0,
  truthCount: 0,
  errorCount: 0,
  timingCount: 0,
  sceneClouds: 0,
  modelClouds: 0,
  webgl: false,
  channels: [],
});

const params = new URLSearchParams(location.search);
const maxRate = Number(params.get('max_rate_hz') ?? '15');
const ws = new WebSocket(`ws://${location.host}/?max_rate_hz=${maxRate}`, [
  FoxgloveClient.SUPPORTED_SUBPROTOCOL,
]);
const client = new FoxgloveClient({ws});
const $ = (id) => document.getElementById(id);

const handlers = {
  '/depth/image': onDepth,
  '/object/pose': onPose,
  '/head/joint_states': onJoints,
  '/diagnostics': onDiagnostics,
  '/target': onTarget,
  '/head/torque_command': onTorque,
  '/sim/ground_truth': onTruth,
  '/timing': onTiming,
  '/object/scene_points': (m) => onCloud('scene', m),
  '/object/model_points': (m) => onCloud('model', m),
};
const subscriptions = new Map();        // subscription id -> { reader, handler }
const channelSubscription = new Map();  // channel id -> subscription id

client.on('open', () => {
  state.connected = true;
  setStatus();
});
client.on('close', () => {
  state.connected = false;
  $('status').textContent = 'disconnected (reload the page to reconnect)';
});
client.on('advertise', (channels) => {
  for (const c of channels) {
    state.channels.push(c.topic);
    const handler = handlers[c.topic];
    if (!handler || c.encoding !== 'cdr' || channelSubscription.has(c.id)) continue;
    const reader = new MessageReader(parse(c.schema, {ros2: true}));
    const id = client.subscribe(c.id);
    subscriptions.set(id, {reader, handler});
    channelSubscription.set(c.id, id);
  }
  setStatus();
});
client.on('unadvertise', (ids) => {
  for (const id of ids) {
    const sub = channelSubscription.get(id);
    subscriptions.delete(sub);
    channelSubscription.delete(id);
  }
});
client.on('status', (s) => console.log(`avs view status ${s.level}: ${s.message}`));
client.on('message', ({subscriptionId, data}) => {
  const sub = subscriptions.get(subscriptionId);
  if (!sub) return;
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  sub.handler(sub.reader.readMessage(bytes));
});

function setStatus() {
  $('status').textContent =
      `${state.connected ? 'connected' : 'connecting'} to ws://${location.host} ` +
      `(images at most ${maxRate} Hz) | channels: ${state.channels.length} | ` +
      `depth frames ${state.depthFrames}, poses ${state.poseCount}, joint states ${
          state.jointCount}`;
}

const stampS = (header) => header.stamp.sec + header.stamp.nanosec * 1e-9;

// ---- depth: 32FC1 metres, red near, blue far (HSV hue 0..240 deg), black where NaN ----
function onDepth(m) {
  if (m.encoding !== '32FC1' || m.width * m.height * 4 > m.data.byteLength) return;
  const view = new DataView(m.data.buffer, m.data.byteOffset, m.data.byteLength);
  const little = !m.is_bigendian;
  const n = m.width * m.height;
  const depth = new Float32Array(n);
  const sample = [];  // every 7th valid depth, for the colour range
  for (let y = 0; y < m.height; y++) {
    for (let x = 0; x < m.width; x++) {
      const d = view.getFloat32(y * m.step + x * 4, little);
      const i = y * m.width + x;
      depth[i] = d;
      if (Number.isFinite(d) && d > 0 && i % 7 === 0) sample.push(d);
    }
  }
  // The colour range spans the 1st to the 99th percentile of the valid depths, not min to max:
  // a single stray pixel metres away (a wrong code at an edge) would otherwise paint the whole
  // scene in the near colour. Depths outside the range take the end colours.
  sample.sort((a, b) => a - b);
  const lo = sample.length ? sample[Math.floor(0.01 * (sample.length - 1))] : 0;
  const hi = sample.length ? sample[Math.ceil(0.99 * (sample.length - 1))] : 1;
  const canvas = $('depth');
  if (canvas.width !== m.width || canvas.height !== m.height) {
    canvas.width = m.width;
    canvas.height = m.height;
  }
  const ctx = canvas.getContext('2d');
  const image = ctx.createImageData(m.width, m.height);
  const span = hi > lo ? hi - lo : 1;
  for (let i = 0; i < n; i++) {
    const d = depth[i];
    let r = 0, g = 0, b = 0;
    if (Number.isFinite(d) && d > 0) {
      [r, g, b] = hue((240 * Math.min(Math.max(d - lo, 0), span)) / span);
    }
    image.data[4 * i] = r;
    image.data[4 * i + 1] = g;
    image.data[4 * i + 2] = b;
    image.data[4 * i + 3] = 255;
  }
  ctx.putImageData(image, 0, 0);
  // The image centre (cross), sized with the image so that it shows at 160 and 512 px.
  const arm = Math.max(6, m.width / 40);
  ctx.lineWidth = Math.max(1, m.width / 256);
  ctx.strokeStyle = '#fff';
  ctx.beginPath();
  ctx.moveTo(m.width / 2 - arm, m.height / 2);
  ctx.lineTo(m.width / 2 + arm, m.height / 2);
  ctx.moveTo(m.width / 2, m.height / 2 - arm);
  ctx.lineTo(m.width / 2, m.height / 2 + arm);
  ctx.stroke();
  drawCentroid(ctx, m.width, m.height);
  state.depthFrames++;
  $('depth-legend').textContent = Number.isFinite(lo) ?
      `${m.width}x${m.height}, ${lo.toFixed(3)} m (red) .. ${hi.toFixed(3)} m (blue), ` +
          `stamp ${stampS(m.header).toFixed(3)} s, frame ${m.header.frame_id}` :
      'no valid depth in the last image';
  setStatus();
}

// ---- /target: the image centroid (m10/m00, m01/m00) the head servoes to the image centre ----
let lastTarget;

function onTarget(m) {
  state.targetCount++;
  lastTarget = m;
  const cx = m.centroid_x_px, cy = m.centroid_y_px;
  $('target-readout').textContent = m.valid ?
      `centroid (${cx.toFixed(1)}, ${cy.toFixed(1)}) px, mean depth ${
          m.mean_depth_m.toFixed(3)} m` :
      'no target in the last depth map';
}

/// A green circle at the last valid centroid, a line from the image centre to it.
function drawCentroid(ctx, w, h) {
  if (!lastTarget || !lastTarget.valid) return;
  const cx = lastTarget.centroid_x_px, cy = lastTarget.centroid_y_px;
  ctx.strokeStyle = '#0f0';
  ctx.beginPath();
  ctx.arc(cx, cy, Math.max(5, w / 50), 0, 2 * Math.PI);
  ctx.moveTo(w / 2, h / 2);
  ctx.lineTo(cx, cy);
  ctx.stroke();
}

function hue(h) {
  const x = 1 - Math.abs(((h / 60) % 2) - 1);
  const [r, g, b] = h < 60 ? [1, x, 0] : h < 120 ? [x, 1, 0] : h < 180 ? [0, 1, x] : [0, x, 1];
  return [255 * r, 255 * g, 255 * b];
}

const poseSeries = new Series();
const jointSeries = new Series();
const torqueSeries = new Series();
const errorSeries = new Series();
const RGB = ['#d33', '#3a3', '#33d'];
const plots = [
  new TimePlot(
      $('pose-plot'), poseSeries,
      [
        {label: 'x', color: RGB[0], scale: 'xy'}, {label: 'y', color: RGB[1], scale: 'xy'},
        {label: 'z', color: RGB[2], scale: 'z'}
      ],
      {xy: 'x, y (mm)', z: 'z (mm)'}),
  new TimePlot(
      $('error-plot'), errorSeries,
      [
        {label: 'position', color: RGB[0], scale: 'mm'},
        {label: 'orientation', color: RGB[2], scale: 'deg'}
      ],
      {mm: 'position (mm)', deg: 'orientation (deg)'}, {height: 160}),
  new TimePlot(
      $('joint-plot'), jointSeries,
      [{label: 'pan', color: RGB[0], scale: 'deg'}, {label: 'tilt', color: RGB[2], scale: 'deg'}],
      {deg: 'angle (deg)'}),
  new TimePlot(
      $('torque-plot'), torqueSeries,
      [{label: 'pan', color: RGB[0], scale: 'nm'}, {label: 'tilt', color: RGB[2], scale: 'nm'}],
      {nm: 'torque (N m)'}),
];

function onPose(m) {
  const p = m.pose.position;
  const q = m.pose.orientation;
  const t = stampS(m.header);
  poseSeries.push(t, [p.x * 1e3, p.y * 1e3, p.z * 1e3]);
  state.poseCount++;
  state.lastPose = {t, p, q};
  matchTruth(stampKey(m.header), {p, q}, undefined);
  $('pose-readout').textContent = `stamp ${t.toFixed(3)} s, frame ${m.header.frame_id}\n` +
      `position (mm)  x ${(p.x * 1e3).toFixed(2)}  y ${(p.y * 1e3).toFixed(2)}  z ${
                                      (p.z * 1e3).toFixed(2)}\n` +
      `quaternion     x ${q.x.toFixed(4)}  y ${q.y.toFixed(4)}  z ${q.z.toFixed(4)}  w ${
                                      q.w.toFixed(4)}`;
}

function onJoints(m) {
  const pan = m.name.indexOf('pan');
  const tilt = m.name.indexOf('tilt');
  if (pan < 0 || tilt < 0) return;
  const deg = 180 / Math.PI;
  jointSeries.push(stampS(m.header), [m.position[pan] * deg, m.position[tilt] * deg]);
  state.jointCount++;
}

function onTorque(m) {
  const pan = m.name.indexOf('pan');
  const tilt = m.name.indexOf('tilt');
  if (pan < 0 || tilt < 0) return;
  torqueSeries.push(stampS(m.header), [m.torque_nm[pan], m.torque_nm[tilt]]);
  state.torqueCount++;
}

// ---- the pose error against /sim/ground_truth (pose_camera), by equal stamps ----
const stampKey = (header) => `${header.stamp.sec}.${header.stamp.nanosec}`;
const pendingPoses = new Map();   // stamp -> pose without its truth yet
const pendingTruths = new Map();  // stamp -> truth without its pose yet
const PENDING = 500;

// /sim/ground_truth has one message per scene object (the target, the wall, ...): the pose is
// compared with the object named by ?object=NAME in the page URL (`avs demo --view` prints
// it), or with the only object there is; with several and no name the panel lists them.
const truthObjects = new Set();
const wantedObject = params.get('object');

function onTruth(m) {
  state.truthCount++;
  const name = m.object_name;
  if (!truthObjects.has(name)) {
    truthObjects.add(name);
    if (!wantedObject && truthObjects.size > 1) {
      pendingTruths.clear();
      errorSeries.clear();
    }
  }
  const compared = wantedObject ?? (truthObjects.size === 1 ? name : undefined);
  if (compared === undefined) {
    $('error-readout').textContent = `/sim/ground_truth has several objects (${
            [...truthObjects].join(', ')}): open the page with ?object=NAME to compare with one`;
    return;
  }
  if (name !== compared) return;
  matchTruth(
      stampKey(m.header), undefined, {p: m.pose_camera.position, q: m.pose_camera.orientation});
}

function matchTruth(key, pose, truth) {
  if (pose) {
    truth = pendingTruths.get(key);
    if (!truth) return remember(pendingPoses, key, pose);
    pendingTruths.delete(key);
  } else {
    pose = pendingPoses.get(key);
    if (!pose) return remember(pendingTruths, key, truth);
    pendingPoses.delete(key);
  }
  const dp = Math.hypot(pose.p.x - truth.p.x, pose.p.y - truth.p.y, pose.p.z - truth.p.z) * 1e3;
  const dot = Math.abs(
      pose.q.x * truth.q.x + pose.q.y * truth.q.y + pose.q.z * truth.q.z + pose.q.w * truth.q.w);
  const deg = (2 * Math.acos(Math.min(1, dot)) * 180) / Math.PI;
  const [sec, nanosec] = key.split('.').map(Number);
  errorSeries.push(sec + nanosec * 1e-9, [dp, deg]);
  state.errorCount++;
  $('error-readout').textContent = `error against /sim/ground_truth of ${wantedObject ?? [
    ...truthObjects
  ][0]}: position ${dp.toFixed(2)} mm, orientation ${deg.toFixed(2)} deg`;
}

function remember(map, key, value) {
  map.set(key, value);
  if (map.size > PENDING) map.delete(map.keys().next().value);  // oldest first
}

// ---- /timing: per stage, the median and the maximum of the last 200 processing times ----
const stageTimes = new Map();  // stage -> recent processing_ms

function onTiming(m) {
  state.timingCount++;
  if (!stageTimes.has(m.stage)) stageTimes.set(m.stage, []);
  const times = stageTimes.get(m.stage);
  times.push(m.processing_ms);
  if (times.length > 200) times.shift();
}

function drawTimings() {
  const rows = [...stageTimes.entries()].sort().map(([stage, times]) => {
    const sorted = [...times].sort((a, b) => a - b);
    const median = sorted[Math.floor(sorted.length / 2)];
    return `${stage.padEnd(10)} median ${median.toFixed(3)} ms  max ${
        sorted[sorted.length - 1].toFixed(3)} ms  (last ${sorted.length}, wall clock)`;
  });
  if (rows.length > 0) $('timings').textContent = rows.join('\n');
}

// ---- 3-D: the S-PCD and the model at its pose ----
const scene3d = new Scene3d($('scene3d'), $('scene3d-note'));
state.webgl = scene3d.ok;

function onCloud(which, m) {
  const xyz = cloudPoints(m);
  if (!xyz) return;
  scene3d.set(which, xyz);
  if (which === 'scene')
    state.sceneClouds++;
  else
    state.modelClouds++;
  if (scene3d.ok) {
    $('scene3d-note').textContent = `${m.header.frame_id}: scene points grey, model red ` +
        `(stamp ${stampS(m.header).toFixed(3)} s); drag to orbit, wheel to zoom`;
  }
}

const diagnosticLines = new Map();  // status name -> its latest line

function onDiagnostics(m) {
  state.diagnosticsCount++;
  // The container's per-component figures (runtime/src/container.cpp): callbacks per second
  // of the graph's clock and the wall-clock time spent in them.
  const figures = (s) => {
    const v = new Map(s.values.map((kv) => [kv.key, kv.value]));
    const parts = [];
    if (v.has('rate_hz')) parts.push(`${Number(v.get('rate_hz')).toFixed(1)} Hz`);
    if (v.has('callback_ms_mean'))
      parts.push(`mean ${Number(v.get('callback_ms_mean')).toFixed(3)} ms`);
    if (v.has('callback_ms_max'))
      parts.push(`max ${Number(v.get('callback_ms_max')).toFixed(3)} ms`);
    return parts.length ? ` (${parts.join(', ')})` : '';
  };
  // Each container (and the server) publishes its own array: keep the latest line per name.
  for (const s of m.status) {
    diagnosticLines.set(
        s.name,
        `${['OK', 'WARN', 'ERROR', 'STALE'][s.level] ?? s.level} ${s.name}: ${s.message}` +
            figures(s));
  }
  const names = [...diagnosticLines.keys()].sort();
  $('diagnostics').textContent = names.slice(0, 40).map((n) => diagnosticLines.get(n)).join('\n');
}

function frame() {
  for (const p of plots) p.update();
  drawTimings();
  scene3d.draw();
  requestAnimationFrame(frame);
}
requestAnimationFrame(frame);
