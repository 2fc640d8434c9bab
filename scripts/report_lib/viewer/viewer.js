// The 3-D view of report.html: draws the scene a beamrail run wrote as VTK files (scripts/report
// turns them into the JSON of <script id="beamrail-scene">), with three.js. Orbit and zoom with the
// mouse; a transient plays its frames, a static analysis shows its deformed state, a mode or
// buckling shape swings; a slider scales the motion. Bundled into the report by esbuild, so the
// page needs no network.
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { LineSegments2 } from "three/examples/jsm/lines/LineSegments2.js";
import { LineSegmentsGeometry } from "three/examples/jsm/lines/LineSegmentsGeometry.js";
import { LineMaterial } from "three/examples/jsm/lines/LineMaterial.js";

function decode(base64, Type) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return new Type(bytes.buffer);
}

function element(id) {
  return document.getElementById(id);
}

class Viewer {
  constructor(box, data) {
    this.data = data;
    this.box = box;
    this.renderer = new THREE.WebGLRenderer({ antialias: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    box.appendChild(this.renderer.domElement);
    this.renderer.domElement.id = "beamrail-canvas";
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xf7f8fa);
    this.camera = new THREE.PerspectiveCamera(40, 1, 1e-3, 1e3);
    this.camera.up.set(0, 0, 1);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.render());
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x667788, 2.2));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(1, -2, 3);
    this.scene.add(sun);
    this.group = new THREE.Group();
    this.scene.add(this.group);
    this.playing = false;
    this.phase = 0;
    this.frame = 0;
    this.renders = 0;
    window.addEventListener("resize", () => this.resize());
  }

  resize() {
    const w = this.box.clientWidth || 800;
    const h = Math.max(320, Math.round(w * 0.55));
    this.renderer.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    for (const m of this.lineMaterials || []) m.resolution.set(w, h);
    this.render();
  }

  // Builds the objects of view `index` (an analysis).
  show(index) {
    this.stop();
    this.group.clear();
    const v = this.data.views[index];
    this.view = v;
    this.positions = v.positions.map((p) => decode(p, Float32Array));
    this.shapes = (v.modes || []).map((m) => decode(m.shape, Float32Array));
    this.nGlyph = v.n_glyph_points;
    const n = v.n_glyph_points + v.n_curve_points;
    this.current = new Float32Array(3 * n);
    this.current.set(this.positions[0]);

    const glyphPositions = new THREE.BufferAttribute(this.current.subarray(0, 3 * v.n_glyph_points), 3);
    glyphPositions.setUsage(THREE.DynamicDrawUsage);
    this.glyphAttribute = glyphPositions;
    const boxes = decode(v.boxes, Int32Array);
    const triangles = [];
    const faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    for (let b = 0; b + 8 <= boxes.length; b += 8)
      for (const f of faces) {
        const q = f.map((k) => boxes[b + k]);
        triangles.push(q[0], q[1], q[2], q[0], q[2], q[3]);
      }
    const boxGeometry = new THREE.BufferGeometry();
    boxGeometry.setAttribute("position", glyphPositions);
    boxGeometry.setIndex(triangles);
    this.boxMesh = new THREE.Mesh(
      boxGeometry,
      new THREE.MeshStandardMaterial({
        color: 0x8fa8c8, flatShading: true, metalness: 0.1, roughness: 0.7,
        side: THREE.DoubleSide, transparent: true, opacity: 0.5,
      }));
    this.group.add(this.boxMesh);
    const levers = decode(v.levers, Int32Array);
    if (levers.length) {
      const leverGeometry = new THREE.BufferGeometry();
      leverGeometry.setAttribute("position", glyphPositions);
      leverGeometry.setIndex(Array.from(levers));
      this.group.add(new THREE.LineSegments(leverGeometry,
                                            new THREE.LineBasicMaterial({ color: 0x555555 })));
    }
    // Curves: fat line segments, coloured per element.
    this.segmentPairs = [];
    const colors = [];
    v.curves.forEach((c, k) => {
      const rgb = (v.curve_colors && v.curve_colors[k]) || (c[2] ? [0.1, 0.55, 0.3] : [0.85, 0.4, 0.1]);
      for (let i = 0; i + 1 < c[1]; ++i) {
        this.segmentPairs.push(v.n_glyph_points + c[0] + i, v.n_glyph_points + c[0] + i + 1);
        colors.push(...rgb, ...rgb);
      }
    });
    this.curveGeometry = new LineSegmentsGeometry();
    this.segmentBuffer = new Float32Array(3 * this.segmentPairs.length);
    this.fillSegments();
    this.curveGeometry.setPositions(this.segmentBuffer);
    if (colors.length) this.curveGeometry.setColors(colors);
    const lineMaterial = new LineMaterial({ linewidth: 4, vertexColors: true });
    this.lineMaterials = [lineMaterial];
    this.curves = new LineSegments2(this.curveGeometry, lineMaterial);
    this.group.add(this.curves);

    const size = v.size || 1;
    const grid = new THREE.GridHelper(2 * size, 20, 0xbbbbbb, 0xdddddd);
    grid.rotation.x = Math.PI / 2;
    grid.position.set(-v.origin[0], -v.origin[1], -v.origin[2]);
    this.group.add(grid);
    const axes = new THREE.AxesHelper(0.15 * size);
    axes.position.copy(grid.position);
    this.group.add(axes);
    // Camera: the bounding sphere of the first frame.
    const bounds = new THREE.Box3().setFromArray(this.positions[0]);
    const centre = bounds.getCenter(new THREE.Vector3());
    const radius = Math.max(bounds.getSize(new THREE.Vector3()).length() / 2, 1e-6 * size, 1e-9);
    this.camera.near = radius / 100;
    this.camera.far = radius * 100;
    this.camera.position.copy(centre).add(new THREE.Vector3(1.2, -2.2, 1.1).multiplyScalar(radius * 1.35));
    this.controls.target.copy(centre);
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.setupControls();
    this.phase = Math.PI / 2;  // a mode shows its largest deflection until it plays
    this.resize();
    this.update();
  }

  fillSegments() {
    const p = this.current, s = this.segmentBuffer;
    for (let k = 0; k < this.segmentPairs.length; ++k) {
      const i = 3 * this.segmentPairs[k];
      s[3 * k] = p[i];
      s[3 * k + 1] = p[i + 1];
      s[3 * k + 2] = p[i + 2];
    }
  }

  setupControls() {
    const v = this.view;
    const modes = element("viewer-mode"), frame = element("viewer-frame"), scale = element("viewer-scale");
    const shaped = v.type === "modal" || v.type === "buckling";
    modes.innerHTML = "";
    (v.modes || []).forEach((m, k) => modes.add(new Option(m.label, String(k))));
    modes.style.display = shaped ? "" : "none";
    frame.max = String(Math.max(0, v.frames.length - 1));
    frame.value = String(v.type === "static" ? v.frames.length - 1 : 0);
    frame.style.display = shaped ? "none" : "";
    this.frame = Number(frame.value);
    // The scale slider: a factor on the motion, logarithmic from 1/10 to 1000 times the default.
    this.defaultScale = v.default_scale || 1;
    scale.min = "-1";
    scale.max = "3";
    scale.step = "0.01";
    scale.value = "0";
    element("viewer-play").textContent = "Play";
    element("viewer-play").disabled = v.type === "static";
  }

  scaleFactor() {
    return this.defaultScale * Math.pow(10, Number(element("viewer-scale").value));
  }

  // Sets the points of the current frame or phase.
  update() {
    const v = this.view, out = this.current, base = this.positions[0];
    const factor = this.scaleFactor();
    if (v.type === "modal" || v.type === "buckling") {
      const m = Number(element("viewer-mode").value || 0);
      const shape = this.shapes[m], start = this.positions[v.modes[m].frame];
      const a = v.modes[m].amplitude * factor / this.defaultScale * Math.sin(this.phase);
      for (let i = 0; i < out.length; ++i) out[i] = start[i] + a * shape[i];
      element("viewer-label").textContent =
        v.modes[m].label + ", amplitude " + (v.modes[m].amplitude * factor / this.defaultScale).toPrecision(3);
    } else {
      const p = this.positions[this.frame];
      for (let i = 0; i < out.length; ++i) out[i] = base[i] + factor * (p[i] - base[i]);
      const f = v.frames[this.frame];
      element("viewer-label").textContent =
        f.label + ", displacements x " + factor.toPrecision(3);
    }
    this.glyphAttribute.needsUpdate = true;
    this.boxMesh.geometry.computeBoundingSphere();
    this.fillSegments();
    this.curveGeometry.setPositions(this.segmentBuffer);
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
    this.renders += 1;
    document.body.dataset.viewerRenders = String(this.renders);
  }

  play() {
    if (this.playing) return this.stop();
    this.playing = true;
    element("viewer-play").textContent = "Pause";
    let last = performance.now();
    const step = (now) => {
      if (!this.playing) return;
      const dt = (now - last) / 1000;
      last = now;
      const v = this.view;
      if (v.type === "modal" || v.type === "buckling") {
        this.phase = (this.phase + dt * 2 * Math.PI / 1.5) % (2 * Math.PI);
      } else {
        // A transient plays its frames in about 8 s.
        this.frameTime = (this.frameTime || 0) + dt * v.frames.length / 8;
        const n = Math.floor(this.frameTime);
        if (n > 0) {
          this.frameTime -= n;
          this.frame = (this.frame + n) % v.frames.length;
          element("viewer-frame").value = String(this.frame);
        }
      }
      this.update();
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  }

  stop() {
    this.playing = false;
    const button = element("viewer-play");
    if (button) button.textContent = "Play";
  }
}

function start() {
  const box = element("viewer-canvas");
  const source = element("beamrail-scene");
  if (!box || !source) return;
  const data = JSON.parse(source.textContent);
  let viewer;
  try {
    viewer = new Viewer(box, data);
  } catch (e) {
    box.textContent = "The 3-D view needs WebGL, which this browser does not offer: " + e.message;
    document.body.dataset.viewerError = String(e.message);
    return;
  }
  window.beamrailViewer = viewer;
  const select = element("viewer-view");
  data.views.forEach((v, k) => select.add(new Option(v.title, String(k))));
  select.addEventListener("change", () => viewer.show(Number(select.value)));
  element("viewer-mode").addEventListener("change", () => {
    viewer.phase = viewer.playing ? viewer.phase : Math.PI / 2;
    viewer.update();
  });
  element("viewer-frame").addEventListener("input", (e) => {
    viewer.frame = Number(e.target.value);
    viewer.update();
  });
  element("viewer-scale").addEventListener("input", () => viewer.update());
  element("viewer-play").addEventListener("click", () => viewer.play());
  viewer.show(0);
  document.body.dataset.viewerReady = "1";
}

if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start);
else start();
