// The page's 3-D panel (docs/view.md): /object/scene_points (the S-PCD, grey) and
// /object/model_points (the model at its pose, red) in camera_optical_frame, drawn with
// three.js, like the paper's Fig. 14. The view starts at the camera (x right, y down, z
// forward) looking down the optical axis; drag to orbit, wheel to zoom. Without WebGL the
// panel says so and the rest of the page goes on.
import * as THREE from 'three';
import {OrbitControls} from 'three/examples/jsm/controls/OrbitControls.js';

/// xyz FLOAT32 fields of a PointCloud2 -> Float32Array of finite points (x, y, z, ...).
export function cloudPoints(m) {
  const field = (name) => m.fields.find((f) => f.name === name && f.datatype === 7);
  const fx = field('x'), fy = field('y'), fz = field('z');
  if (!fx || !fy || !fz) return undefined;
  const n = m.width * m.height;
  if (n * m.point_step > m.data.byteLength) return undefined;
  const view = new DataView(m.data.buffer, m.data.byteOffset, m.data.byteLength);
  const little = !m.is_bigendian;
  const out = new Float32Array(3 * n);
  let k = 0;
  for (let i = 0; i < n; i++) {
    const o = i * m.point_step;
    const x = view.getFloat32(o + fx.offset, little);
    const y = view.getFloat32(o + fy.offset, little);
    const z = view.getFloat32(o + fz.offset, little);
    if (!Number.isFinite(x) || !Number.isFinite(y) || !Number.isFinite(z)) continue;
    out[k++] = x;
    out[k++] = y;
    out[k++] = z;
  }
  return out.subarray(0, k);
}

export class Scene3d {
  /// canvas: the panel's canvas; note: an element for one line of text under it.
  constructor(canvas, note) {
    this.note = note;
    this.ok = false;
    try {
      this.renderer =
          new THREE.WebGLRenderer({canvas, antialias: true, preserveDrawingBuffer: true});
    } catch (e) {
      note.textContent = `no 3-D view: this browser gives no WebGL (${e.message})`;
      return;
    }
    this.renderer.setClearColor(0x101018);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, canvas.width / canvas.height, 0.01, 50);
    // At the optical centre, looking along +z with image "up" (-y) up.
    this.camera.position.set(0, 0, -0.05);
    this.camera.up.set(0, -1, 0);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.target.set(0, 0, 1);
    this.controls.update();
    // Rendered only when something changed: a software WebGL renderer costs a browser core.
    this.dirty = true;
    this.controls.addEventListener('change', () => (this.dirty = true));
    // The camera frame's axes: x orange, y green, z blue (red is the model's).
    const axes = new THREE.AxesHelper(0.1);
    axes.setColors(0xffaa00, 0x00ff00, 0x4080ff);
    this.scene.add(axes);
    this.clouds = {
      scene: this.makeCloud(0xb0b0b0, 0.004),
      model: this.makeCloud(0xff3030, 0.006),
    };
    this.framed = false;
    this.ok = true;
  }

  makeCloud(color, size) {
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(0), 3));
    const points = new THREE.Points(geometry, new THREE.PointsMaterial({color, size}));
    this.scene.add(points);
    return points;
  }

  /// which: 'scene' or 'model'; xyz: Float32Array from cloudPoints().
  set(which, xyz) {
    if (!this.ok) return;
    const cloud = this.clouds[which];
    cloud.geometry.setAttribute('position', new THREE.BufferAttribute(xyz, 3));
    cloud.geometry.computeBoundingSphere();
    this.dirty = true;
    if (!this.framed && which === 'scene' && xyz.length >= 3) {
      // Aim once at the first scene cloud, from slightly above the optical centre's line of
      // sight and near enough that the cloud fills about half the view; the user's orbit is
      // kept after that.
      const {center: c, radius} = cloud.geometry.boundingSphere;
      const eye = new THREE.Vector3(c.x, c.y - 0.2 * c.z, 0);
      const sight = c.clone().sub(eye).normalize();
      const halfFov = THREE.MathUtils.degToRad(this.camera.fov / 2);
      const distance = Math.max(2 * radius / Math.sin(halfFov), 0.05);
      this.controls.target.copy(c);
      this.camera.position.copy(c.clone().addScaledVector(sight, -distance));
      this.controls.update();
      this.framed = true;
    }
  }

  /// Renders if a cloud or the view changed since the last call.
  draw() {
    if (!this.ok || !this.dirty) return;
    this.dirty = false;
    this.renderer.render(this.scene, this.camera);
  }
}
