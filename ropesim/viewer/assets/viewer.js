/* ropesim's run viewer: draws the runs described in #ropesim-description with three.js (the global THREE).

The page holds a JSON description (runs: lines, points, bodies, shapes, water, seabed, series, summary; see
ropesim/viewer/pack.py) and one zlib-compressed, base64-coded buffer of arrays (#ropesim-data). Everything is
decoded once, then each shown frame is dequantised on the fly from 16-bit integers.

window.ropesim is a small hook for tests and benchmarks: state(), info(), setFrame(i), play(), pause(),
positions(run, line), bodyPose(run, body), and the promise `ready` (the first frame is on the screen).
*/
(function () {
  "use strict";

  const Q16_NOT_FINITE = 65535, Q8_NOT_FINITE = 255, FIELD_LEVELS = 254;
  const SPEEDS = [0.01, 0.02, 0.05, 0.1, 0.25, 0.5, 1, 2, 5, 10, 20, 50, 100];
  const LINE_WIDTH = 2.5;                         // [CSS px]
  const BACKGROUND = 0xf3f5f7, GEOMETRY_FILL = 0xe6e6e6, GEOMETRY_EDGE = 0x737373;
  const $ = (id) => document.getElementById(id);
  const ICON = (d) => `<svg viewBox="0 0 16 16" width="14" height="14" aria-hidden="true"><path d="${d}"/></svg>`;
  const PLAY = ICON("M4 2v12l10-6z"), PAUSE = ICON("M3 2h4v12H3zM9 2h4v12H9z");

  const hook = { renders: 0, firstFrameMs: null, decodeMs: null, error: null };
  let resolveReady, rejectReady;
  hook.ready = new Promise((res, rej) => { resolveReady = res; rejectReady = rej; });
  hook.ready.catch(() => {});      // a failure is shown in the page and logged once (fail), not again unhandled
  window.ropesim = hook;

  // ------------------------------------------------------------------------------------------- data

  async function inflate(text) {
    let bytes;
    if (Uint8Array.fromBase64) {
      bytes = Uint8Array.fromBase64(text.trim());
    } else {
      const binary = atob(text.trim());
      bytes = new Uint8Array(binary.length);
      for (let i = 0; i < binary.length; i++) bytes[i] = binary.charCodeAt(i);
    }
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // A ribbon's vertex: at ``position``, the other end of its segment at ``other``; pushed ``side`` (+1 or -1)
  // half a width across the segment as the screen shows it, and half a width out beyond its own end.
  const RIBBON_VERTEX = `
    uniform vec2 resolution;
    uniform float width;
    attribute vec3 other;
    attribute float side;
    varying vec3 vColor;
    void main() {
      vColor = color;
      vec4 here = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
      vec4 there = projectionMatrix * modelViewMatrix * vec4(other, 1.0);
      vec2 a = here.xy / here.w * resolution, b = there.xy / there.w * resolution;
      vec2 along = b - a;
      float len = length(along);
      along = len > 1e-6 ? along / len : vec2(1.0, 0.0);
      vec2 across = vec2(-along.y, along.x);
      vec2 shift = (side * across - along) * width / resolution;   // [clip units]: pixels * 2 / size, halved
      gl_Position = here;
      gl_Position.xy += shift * here.w;
    }`;
  const RIBBON_FRAGMENT = `
    varying vec3 vColor;
    void main() { gl_FragColor = vec4(vColor, 1.0); }`;

  const TYPES = { u16: Uint16Array, u8: Uint8Array, f32: Float32Array, f64: Float64Array };

  /** The array a reference names, decoded in place: "delta-along" adds back the differences along the last
   * axis, "delta-time-along" those and then the differences between frames (axis 0), modulo 2^bits. */
  function decode(buffer, ref) {
    if (ref === undefined || ref === null || Array.isArray(ref)) return ref;
    const count = ref.shape.reduce((a, b) => a * b, 1);
    const a = new TYPES[ref.dtype](buffer.buffer, buffer.byteOffset + ref.offset, count);
    if (ref.coding === "delta-along" || ref.coding === "delta-time-along") {
      const along = ref.shape[ref.shape.length - 1];
      for (let base = 0; base < count; base += along) {
        for (let k = 1; k < along; k++) a[base + k] += a[base + k - 1];
      }
    }
    if (ref.coding === "delta-time-along") {
      const row = count / ref.shape[0];
      for (let i = row; i < count; i++) a[i] += a[i - row];
    }
    return a;
  }

  function decodeAll(description, buffer) {
    for (const run of description.runs) {
      run.time = decode(buffer, run.time);
      for (const line of run.lines) {
        line.positions = decode(buffer, line.positions);
        for (const f of line.fields) f.values = decode(buffer, f.values);
      }
      for (const p of run.points) if (p.positions) p.positions = decode(buffer, p.positions);
      for (const b of run.bodies) {
        b.position = decode(buffer, b.position);
        b.orientation = decode(buffer, b.orientation);
      }
      for (const s of [run.water, run.seabed]) if (s && s.heights) s.heights = decode(buffer, s.heights);
      for (const s of run.series) s.values = decode(buffer, s.values);
    }
  }

  /** Coordinates of node k of a quantised (F, D, K) array at frame f, as [x, y, z] (z = 0 in 2-D); null when
   * not finite. */
  function nodePosition(run, array, count, f, k, out) {
    const q = run.quantisation, d = run.dimension;
    for (let c = 0; c < 3; c++) {
      if (c >= d) { out[c] = 0; continue; }
      const v = array[(f * d + c) * count + k];
      if (v === Q16_NOT_FINITE) return null;
      out[c] = q.origin[c] + q.step * v;
    }
    return out;
  }

  // ------------------------------------------------------------------------------------------ maths

  function niceStep(span, target) {
    const raw = span / Math.max(target, 1);
    const power = Math.pow(10, Math.floor(Math.log10(raw)));
    for (const m of [1, 2, 5, 10]) if (m * power >= raw) return m * power;
    return 10 * power;
  }

  function format(value, unit) {
    if (!isFinite(value)) return "–";
    let v = value, u = unit;
    if (unit === "N") {
      const a = Math.abs(value);
      if (a >= 1e6) { v = value / 1e6; u = "MN"; } else if (a >= 1e4) { v = value / 1e3; u = "kN"; }
    }
    const a = Math.abs(v);
    // trailing zeros go only after a decimal point: 7440 stays 7440, 2.500 is 2.5
    const text = a !== 0 && (a < 1e-3 || a >= 1e5) ? v.toExponential(2)
      : v.toPrecision(4).replace(/(\.\d*?)0+$/, "$1").replace(/\.$/, "");
    return u ? `${text} ${u}` : text;
  }

  /** A unit for values up to ``largest``: N as kN or MN where that reads better; (factor, unit). */
  function scaled(unit, largest) {
    if (unit === "N" && largest >= 1e6) return [1e-6, "MN"];
    if (unit === "N" && largest >= 1e4) return [1e-3, "kN"];
    return [1, unit];
  }

  function srgb(hex) {
    return [1, 3, 5].map((i) => parseInt(hex.substr(i, 2), 16) / 255);
  }

  function lastAtOrBefore(times, t) {          // index of the last time <= t (0 if none)
    let lo = 0, hi = times.length - 1;
    if (t <= times[0]) return 0;
    while (lo < hi) {
      const mid = (lo + hi + 1) >> 1;
      if (times[mid] <= t * (1 + 1e-12) + 1e-12) lo = mid; else hi = mid - 1;
    }
    return lo;
  }

  /** True when WebGL is drawn by the CPU (SwiftShader, llvmpipe): no graphics card to lean on. */
  function softwareWebGL() {
    const gl = document.createElement("canvas").getContext("webgl");
    const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
    const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
    return /swiftshader|llvmpipe|software/i.test(name);
  }

  // -------------------------------------------------------------------------------------- the viewer

  class Viewer {
    constructor(description) {
      this.d = description;
      this.runs = description.runs;
      this.dimension = this.runs[0].dimension;
      this.colormap = this.colormapOf(description.colormap);
      this.times = this.mergedTimes();
      this.index = 0;                     // into this.times
      this.playing = false;
      this.speed = 1;
      this.colorBy = this.runs.length > 1 ? "run" : (this.fieldNames()[0] || "run");
      this.needsRender = true;
      this.tmp = [0, 0, 0];
      this.extent = this.sceneExtent();
      this.relative = this.followedExtent();
      // a towed line that travels far beyond its own size is seen from its driven node, as `ropesim frames --follow`
      this.follow = !!this.relative && this.extent.size > 4 * this.relative.size;
      this.setUpRenderer();
      this.setUpScene();
      this.setUpControls();
      this.setUpPanel();
      this.showFrame(0);
    }

    colormapOf(hex) {
      const table = new Float32Array(256 * 3);
      for (let i = 0; i < 256 * 3; i++) table[i] = parseInt(hex.substr(2 * i, 2), 16) / 255;
      return table;
    }

    mergedTimes() {
      const all = [];
      for (const run of this.runs) for (const t of run.time) all.push(t);
      all.sort((a, b) => a - b);
      const out = [];
      for (const t of all) if (!out.length || t - out[out.length - 1] > 1e-12 * Math.max(1, Math.abs(t))) out.push(t);
      return Float64Array.from(out);
    }

    fieldNames() {
      const names = [];
      for (const run of this.runs) for (const line of run.lines) for (const f of line.fields)
        if (!names.includes(f.name)) names.push(f.name);
      return names;
    }

    sceneExtent() {
      const { lo, hi } = this.tightExtent();
      for (const run of this.runs) {
        for (const b of run.bodies) if (b.fixed) {
          const r = 0.5 * Math.hypot(...b.size);
          for (let c = 0; c < run.dimension; c++) { lo[c] = Math.min(lo[c], b.position[c] - r); hi[c] = Math.max(hi[c], b.position[c] + r); }
        }
        for (const s of run.shapes) for (let c = 0; c < 2; c++) {
          lo[c] = Math.min(lo[c], s.center[c] - s.radius); hi[c] = Math.max(hi[c], s.center[c] + s.radius);
        }
      }
      const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3);
      return { lo, hi, size, center: [0, 1, 2].map((c) => (lo[c] + hi[c]) / 2) };
    }

    /** The first run's driven nodes (line 0), the followed point: their centre at frame f, or null. */
    drivenCentre(run, f) {
      const p = run.points.find((pp) => pp.kind === "driven" && pp.line !== undefined);
      if (!p) return null;
      const line = run.lines[p.line], c = [0, 0, 0], tmp = [0, 0, 0];
      for (const k of p.nodes) {
        const r = nodePosition(run, line.positions, line.nodes, f, k, tmp);
        if (!r) return null;
        for (let i = 0; i < 3; i++) c[i] += r[i] / p.nodes.length;
      }
      return c;
    }

    /** The box of the first followable run's lines seen from its driven nodes, over all frames, or null. */
    followedExtent() {
      const run = this.runs.find((r) => this.drivenCentre(r, 0));
      if (!run) return null;
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity], tmp = [0, 0, 0];
      for (let f = 0; f < run.frames; f++) {
        const c = this.drivenCentre(run, f);
        if (!c) continue;
        for (const line of run.lines) for (let k = 0; k < line.nodes; k++) {
          const p = nodePosition(run, line.positions, line.nodes, f, k, tmp);
          if (!p) continue;
          for (let i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], p[i] - c[i]); hi[i] = Math.max(hi[i], p[i] - c[i]); }
        }
      }
      if (!(lo[0] <= hi[0])) return null;
      const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-3);
      return { lo, hi, size, center: [0, 1, 2].map((i) => (lo[i] + hi[i]) / 2), run };
    }

    /** The box of every line's finite nodes over all frames (scanned once from the integers). */
    tightExtent() {
      const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
      for (const run of this.runs) {
        const d = run.dimension, q = run.quantisation;
        const arrays = run.lines.map((l) => [l.positions, l.nodes]);
        for (const p of run.points) if (p.positions) arrays.push([p.positions, p.positions.length / (run.frames * d)]);
        for (const [a, count] of arrays) {
          for (let c = 0; c < d; c++) {
            let mn = Infinity, mx = -Infinity;
            for (let f = 0; f < run.frames; f++) {
              const base = (f * d + c) * count;
              for (let k = 0; k < count; k++) {
                const v = a[base + k];
                if (v !== Q16_NOT_FINITE) { if (v < mn) mn = v; if (v > mx) mx = v; }
              }
            }
            if (mn <= mx) {
              lo[c] = Math.min(lo[c], q.origin[c] + q.step * mn);
              hi[c] = Math.max(hi[c], q.origin[c] + q.step * mx);
            }
          }
        }
        for (let c = d; c < 3; c++) { lo[c] = Math.min(lo[c], 0); hi[c] = Math.max(hi[c], 0); }
      }
      for (let c = 0; c < 3; c++) if (!(lo[c] <= hi[c])) { lo[c] = 0; hi[c] = 0; }
      return { lo, hi };
    }

    // ----- three.js set-up

    setUpRenderer() {
      const host = $("view");
      // multisampling is nearly free on a graphics card and costs a quarter of the frame rate in software WebGL
      this.renderer = new THREE.WebGLRenderer({ antialias: !softwareWebGL() });
      this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
      this.renderer.setClearColor(BACKGROUND);
      this.renderer.autoClear = false;
      host.appendChild(this.renderer.domElement);
      this.renderer.domElement.id = "canvas";
      this.scene = new THREE.Scene();
      const e = this.extent;
      if (this.dimension === 2) {
        this.camera = new THREE.OrthographicCamera(-1, 1, 1, -1, -10 * e.size, 10 * e.size);
      } else {
        this.camera = new THREE.PerspectiveCamera(35, 1, e.size / 1000, e.size * 100);
      }
      this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 2.2));
      const sun = new THREE.DirectionalLight(0xffffff, 1.2);
      sun.position.set(0.4, 1, 0.7);
      this.scene.add(sun);
      new ResizeObserver(() => this.resize()).observe(host);
    }

    resize() {
      const host = $("view");
      const w = Math.max(host.clientWidth, 1), h = Math.max(host.clientHeight, 1);
      this.renderer.setSize(w, h);
      this.width = w; this.height = h;
      for (const m of this.lineMaterials || []) m.uniforms.resolution.value.set(w, h);
      if (this.dimension === 2) this.fitOrthographic(false);
      else { this.camera.aspect = w / h; this.camera.updateProjectionMatrix(); }
      if (this.controls && !this.moved) this.resetView();       // the first view fits whatever the page's size
      this.drawSeries();
      this.requestRender();
    }

    /** What the first view frames: the whole run, or (following) the line around its driven nodes now. */
    framed() {
      if (this.follow && this.relative) {
        const c = this.drivenCentre(this.relative.run, this.frameOf(this.relative.run)) || [0, 0, 0];
        const r = this.relative;
        return { lo: r.lo.map((v, i) => v + c[i]), hi: r.hi.map((v, i) => v + c[i]), size: r.size,
                 center: r.center.map((v, i) => v + c[i]) };
      }
      return this.extent;
    }

    fitOrthographic(reset) {
      const cam = this.camera, aspect = this.width / this.height;
      if (reset || this.halfHeight === undefined) {
        const e = this.framed();
        const w = (e.hi[0] - e.lo[0]) * 1.25 || 1, h = (e.hi[1] - e.lo[1]) * 1.15 || 1;   // room for the legend and the colour bar
        this.halfHeight = Math.max(h, w / aspect) / 2;
      }
      cam.left = -this.halfHeight * aspect; cam.right = this.halfHeight * aspect;
      cam.top = this.halfHeight; cam.bottom = -this.halfHeight;
      cam.updateProjectionMatrix();
    }

    resetView() {
      const e = this.framed(), c = e.center;
      this.controls.target.set(c[0], c[1], c[2]);
      if (this.dimension === 2) {
        this.camera.position.set(c[0], c[1], c[2] + 2 * this.extent.size);
        this.camera.zoom = 1;
        this.fitOrthographic(true);
      } else {
        const dir = new THREE.Vector3(0.55, 0.35, 1).normalize();
        const dist = 0.62 * e.size / Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2)) + e.size / 2;
        this.camera.position.set(c[0] + dir.x * dist, c[1] + dir.y * dist, c[2] + dir.z * dist);
      }
      this.camera.lookAt(c[0], c[1], c[2]);
      this.controls.update();
      this.followed = this.follow && this.relative ? this.drivenCentre(this.relative.run, this.frameOf(this.relative.run)) : null;
      if (this.followed) this.grids.relative.position.set(...this.followed);
      this.moved = false;
      this.showGrid();
      this.requestRender();
    }

    setUpScene() {
      const e = this.extent;
      this.lineMaterials = [];
      this.drawn = [];
      for (const [r, run] of this.runs.entries()) {
        const group = new THREE.Group();
        const parts = { group, lines: [], points: [], bodies: [], water: null };
        for (const line of run.lines) parts.lines.push(this.makeLine(run, line));
        for (const p of run.points) parts.points.push(this.makePoints(run, p));
        for (const b of run.bodies) parts.bodies.push(this.makeBody(run, b));
        for (const s of run.shapes) group.add(this.makeShape(run, s));
        if (run.seabed) group.add(this.makeSeabed(run.seabed));
        if (run.water) { parts.water = this.makeWater(run.water); group.add(parts.water.object); }
        for (const l of parts.lines) group.add(l.object);
        for (const p of parts.points) group.add(p.object);
        for (const b of parts.bodies) group.add(b.object);
        this.scene.add(group);
        this.drawn.push(parts);
        parts.run = r;
      }
      this.grids = { absolute: this.makeGrid(this.extent, false), relative: null };
      this.scene.add(this.grids.absolute);
      if (this.relative) {
        this.grids.relative = this.makeGrid(this.relative, true);
        this.scene.add(this.grids.relative);
      }
      this.makeTriad();
    }

    /** A line as a ribbon LINE_WIDTH pixels wide: a quad per segment, widened on the screen by the vertex
     * shader, each end pushed out by half the width so that neighbours overlap at the joints. (three.js's own
     * fat lines draw each segment as an instance, which software WebGL (SwiftShader) draws one by one: a 2000-node
     * line took 35 ms a frame, this one a few.) */
    makeLine(run, line) {
      const segments = Math.max(line.closed ? line.nodes : line.nodes - 1, 1);
      const geometry = new THREE.BufferGeometry();
      const attribute = (size, dynamic) => {
        const a = new THREE.BufferAttribute(new Float32Array(4 * segments * size), size);
        if (dynamic) a.setUsage(THREE.DynamicDrawUsage);
        return a;
      };
      geometry.setAttribute("position", attribute(3, true));
      geometry.setAttribute("other", attribute(3, true));
      geometry.setAttribute("color", attribute(3, true));
      const side = attribute(1, false), index = new Uint32Array(6 * segments);
      for (let s = 0; s < segments; s++) {
        side.array.set([1, -1, -1, 1], 4 * s);          // the far end's normal is turned round: -1 is its +1
        const v = 4 * s;
        index.set([v, v + 1, v + 2, v + 2, v + 1, v + 3], 6 * s);
      }
      geometry.setAttribute("side", side);
      geometry.setIndex(new THREE.BufferAttribute(index, 1));
      const material = new THREE.ShaderMaterial({
        uniforms: { resolution: { value: new THREE.Vector2(1, 1) }, width: { value: LINE_WIDTH } },
        vertexShader: RIBBON_VERTEX, fragmentShader: RIBBON_FRAGMENT, side: THREE.DoubleSide, vertexColors: true,
      });
      this.lineMaterials.push(material);
      const object = new THREE.Mesh(geometry, material);
      object.frustumCulled = false;
      object.renderOrder = 2;
      return { object, line, segments: line.closed ? line.nodes : line.nodes - 1, geometry,
               positions: geometry.attributes.position.array, others: geometry.attributes.other.array,
               colors: geometry.attributes.color.array };
    }

    glyph(kind) {
      const size = 64, canvas = document.createElement("canvas");
      canvas.width = canvas.height = size;
      const g = canvas.getContext("2d");
      g.fillStyle = "#ffffff";
      g.beginPath();
      const c = size / 2, r = size / 2 - 2;
      if (kind === "pinned") g.rect(c - 0.8 * r, c - 0.8 * r, 1.6 * r, 1.6 * r);
      else if (kind === "driven") { g.moveTo(c - r, c - 0.75 * r); g.lineTo(c + r, c - 0.75 * r); g.lineTo(c, c + r); }
      else if (kind === "parachute") { g.moveTo(c + r, c + 0.35 * r); g.arc(c, c + 0.35 * r, r, 0, Math.PI, true); }
      else g.arc(c, c, kind === "point" ? 0.6 * r : r, 0, 2 * Math.PI);
      g.closePath();
      g.fill();
      const texture = new THREE.CanvasTexture(canvas);
      texture.colorSpace = THREE.SRGBColorSpace;
      return texture;
    }

    makePoints(run, p) {
      const count = p.positions ? p.positions.length / (run.frames * run.dimension) : p.nodes.length;
      const geometry = new THREE.BufferGeometry();
      const positions = new Float32Array(3 * count);
      geometry.setAttribute("position", new THREE.BufferAttribute(positions, 3));
      const material = new THREE.PointsMaterial({
        size: p.size * (this.renderer.getPixelRatio()), sizeAttenuation: false, map: this.glyph(p.kind),
        color: new THREE.Color(p.color), alphaTest: 0.5, transparent: false, depthTest: false,
      });
      const object = new THREE.Points(geometry, material);
      object.frustumCulled = false;
      object.renderOrder = 5;
      return { object, p, count, positions, geometry };
    }

    makeBody(run, b) {
      const group = new THREE.Group();
      const [sx, sy, sz] = b.size;
      const flat = this.dimension === 2 || sz === 0;
      const geometry = flat ? new THREE.PlaneGeometry(sx, sy) : new THREE.BoxGeometry(sx, sy, sz);
      const color = new THREE.Color(b.color);
      const fill = new THREE.Mesh(geometry, b.fixed
        ? new THREE.MeshBasicMaterial({ color, transparent: true, opacity: flat ? 1 : 0.45, depthWrite: false, side: THREE.DoubleSide })
        : new THREE.MeshLambertMaterial({ color }));
      fill.renderOrder = 0;
      const edges = new THREE.LineSegments(new THREE.EdgesGeometry(geometry),
                                           new THREE.LineBasicMaterial({ color: GEOMETRY_EDGE }));
      edges.renderOrder = 1;
      group.add(fill, edges);
      if (flat) group.position.z = -1e-3 * this.extent.size;    // behind the line in a flat view
      this.poseBody(run, b, group, 0);
      return { object: group, b };
    }

    poseBody(run, b, object, f) {
      const d = run.dimension;
      const p = Array.isArray(b.position) ? b.position : b.position.subarray(f * d, f * d + d);
      const q = Array.isArray(b.orientation) ? b.orientation : b.orientation.subarray(4 * f, 4 * f + 4);
      object.position.set(p[0], p[1], d > 2 ? p[2] : object.position.z);
      object.quaternion.set(q[1], q[2], q[3], q[0]).normalize();     // stored w, x, y, z
    }

    makeShape(run, s) {
      const group = new THREE.Group();
      const material = s.dashed
        ? new THREE.LineDashedMaterial({ color: GEOMETRY_EDGE, dashSize: s.radius * 0.15, gapSize: s.radius * 0.1 })
        : new THREE.LineBasicMaterial({ color: GEOMETRY_EDGE });
      const circle = () => {
        const pts = [];
        for (let i = 0; i <= 96; i++) {
          const a = (i / 96) * 2 * Math.PI;
          pts.push(new THREE.Vector3(s.radius * Math.cos(a), s.radius * Math.sin(a), 0));
        }
        const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), material);
        line.computeLineDistances();
        return line;
      };
      const axis = new THREE.Vector3(...s.axis).normalize();
      if (this.dimension === 2) {
        group.add(circle());
      } else {
        const e = this.extent;
        const along = [0, 1, 2].map((c) => [e.lo[c], e.hi[c]]);
        let lo = Infinity, hi = -Infinity;   // the run's extent along the axis, from the shape's centre
        for (const x of along[0]) for (const y of along[1]) for (const z of along[2]) {
          const t = (x - s.center[0]) * axis.x + (y - s.center[1]) * axis.y + (z - s.center[2]) * axis.z;
          lo = Math.min(lo, t); hi = Math.max(hi, t);
        }
        const pad = 0.1 * e.size, length = hi - lo + 2 * pad, middle = (hi + lo) / 2;
        const tube = new THREE.Mesh(new THREE.CylinderGeometry(s.radius, s.radius, length, 64, 1, true),
          new THREE.MeshBasicMaterial({ color: GEOMETRY_FILL, transparent: true, opacity: 0.35, depthWrite: false, side: THREE.DoubleSide }));
        tube.rotation.x = Math.PI / 2;        // the cylinder's own axis (y) along z
        tube.position.z = middle;
        group.add(tube);
        for (const z of [middle - length / 2, middle + length / 2]) {
          const rim = circle();
          rim.position.z = z;
          group.add(rim);
        }
      }
      group.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), axis);
      group.position.set(s.center[0], s.center[1], s.center[2] || 0);
      return group;
    }

    planeSpan() {
      const e = this.extent, pad = 0.6 * e.size;
      return { x0: e.lo[0] - pad, x1: e.hi[0] + pad, z0: e.lo[2] - pad, z1: e.hi[2] + pad, y0: e.lo[1] - pad };
    }

    /** A surface y = height + tan(slope) x, or a height grid, as a mesh (3-D) or its edge and what lies below
     * or above it (2-D); ``below``: fill downwards (the seabed) or down to the seabed (water). */
    makeSurface(surface, color, opacity, fillBelow) {
      const s = this.planeSpan(), tan = Math.tan(THREE.MathUtils.degToRad(surface.slope_deg || 0));
      const yAt = (x) => surface.height + tan * x;
      if (this.dimension === 2) {
        const group = new THREE.Group();
        const depth = fillBelow ? s.y0 - this.extent.size : Math.min(s.y0, yAt(s.x0), yAt(s.x1));
        const shape = new THREE.Shape([new THREE.Vector2(s.x0, yAt(s.x0)), new THREE.Vector2(s.x1, yAt(s.x1)),
                                       new THREE.Vector2(s.x1, depth), new THREE.Vector2(s.x0, depth)]);
        const fill = new THREE.Mesh(new THREE.ShapeGeometry(shape),
          new THREE.MeshBasicMaterial({ color, transparent: opacity < 1, opacity, depthWrite: false }));
        fill.position.z = -2e-3 * this.extent.size;
        const edge = new THREE.Line(new THREE.BufferGeometry().setFromPoints(
          [new THREE.Vector3(s.x0, yAt(s.x0), 0), new THREE.Vector3(s.x1, yAt(s.x1), 0)]),
          new THREE.LineBasicMaterial({ color: GEOMETRY_EDGE }));
        group.add(fill, edge);
        return { object: group };
      }
      let geometry;
      if (surface.heights) {
        const nx = surface.x.length, nz = surface.z.length;
        geometry = new THREE.BufferGeometry();
        const pos = new Float32Array(3 * nx * nz), index = [];
        for (let i = 0; i < nx; i++) for (let j = 0; j < nz; j++) {
          pos[3 * (i * nz + j)] = surface.x[i]; pos[3 * (i * nz + j) + 2] = surface.z[j];
          if (i + 1 < nx && j + 1 < nz) {
            const a = i * nz + j, b = a + nz;
            index.push(a, a + 1, b, b, a + 1, b + 1);
          }
        }
        geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
        geometry.setIndex(index);
      } else {
        geometry = new THREE.BufferGeometry();
        const pos = new Float32Array([s.x0, yAt(s.x0), s.z0, s.x1, yAt(s.x1), s.z0, s.x1, yAt(s.x1), s.z1,
                                      s.x0, yAt(s.x0), s.z1]);
        geometry.setAttribute("position", new THREE.BufferAttribute(pos, 3));
        geometry.setIndex([0, 2, 1, 0, 3, 2]);
      }
      geometry.computeVertexNormals();
      const mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial(
        { color, transparent: opacity < 1, opacity, side: THREE.DoubleSide, depthWrite: opacity >= 1 }));
      return { object: mesh, surface };
    }

    makeSeabed(seabed) {
      return this.makeSurface(seabed, 0xd8ccb4, this.dimension === 2 ? 1 : 0.9, true).object;
    }

    makeWater(water) {
      return this.makeSurface(water, 0x4f9bd9, 0.25, false);
    }

    moveWater(water, f) {
      const s = water.surface;
      if (!s || !s.heights || this.dimension === 2) return;
      const nx = s.x.length, nz = s.z.length, perFrame = s.heights.length > nx * nz;
      const base = perFrame ? f * nx * nz : 0;
      const pos = water.object.geometry.attributes.position;
      for (let i = 0; i < nx * nz; i++) pos.array[3 * i + 1] = s.heights[base + i];
      pos.needsUpdate = true;
      water.object.geometry.computeVertexNormals();
    }

    /** A grid under the run (3-D: at its lowest point; 2-D: behind it) over the box ``e``; ``relative``: a
     * grid around the driven node that moves with it. */
    makeGrid(e, relative) {
      const group = new THREE.Group();
      const step = niceStep(e.size, 8);
      const material = new THREE.LineBasicMaterial({ color: 0xc9ced6 });
      const pts = [];
      const bAxis = this.dimension === 2 ? 1 : 2;
      const pad = this.dimension === 2 ? 2 * e.size : 0;   // a flat view pans and zooms out over more of it
      const a0 = Math.floor((e.lo[0] - pad) / step) * step, a1 = Math.ceil((e.hi[0] + pad) / step) * step;
      const b0 = Math.floor((e.lo[bAxis] - pad) / step) * step, b1 = Math.ceil((e.hi[bAxis] + pad) / step) * step;
      const at = (a, b) => (this.dimension === 2 ? new THREE.Vector3(a, b, -3e-3 * this.extent.size)
                                                 : new THREE.Vector3(a, e.lo[1], b));
      for (let a = a0; a <= a1 + step / 2; a += step) pts.push(at(a, b0), at(a, b1));
      for (let b = b0; b <= b1 + step / 2; b += step) pts.push(at(a0, b), at(a1, b));
      const grid = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(pts), material);
      grid.renderOrder = -1;
      group.add(grid);
      group.userData.note = `grid ${format(step, "m")}` + (relative ? ", moving with the driven node"
        : this.dimension === 3 ? " (at the lowest point)" : "");
      return group;
    }

    showGrid() {
      const following = this.follow && !!this.grids.relative;
      this.grids.absolute.visible = !following;
      if (this.grids.relative) this.grids.relative.visible = following;
      $("grid-note").textContent = (following ? this.grids.relative : this.grids.absolute).userData.note;
    }

    makeTriad() {
      this.triadScene = new THREE.Scene();
      this.triadCamera = new THREE.OrthographicCamera(-1.6, 1.6, 1.6, -1.6, 0.1, 10);
      const colors = [0xd62728, 0x2ca02c, 0x1f77b4];
      for (let c = 0; c < 3; c++) {
        if (this.dimension === 2 && c === 2) continue;
        const dir = new THREE.Vector3(c === 0, c === 1, c === 2);
        this.triadScene.add(new THREE.ArrowHelper(dir, new THREE.Vector3(), 1, colors[c], 0.3, 0.15));
        const canvas = document.createElement("canvas");
        canvas.width = canvas.height = 64;
        const g = canvas.getContext("2d");
        g.font = "bold 44px sans-serif"; g.textAlign = "center"; g.textBaseline = "middle";
        g.fillStyle = "#" + colors[c].toString(16).padStart(6, "0");
        g.fillText((this.runs[0].axes || ["x", "y", "z"])[c], 32, 34);
        const texture = new THREE.CanvasTexture(canvas);
        const label = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false }));
        label.position.copy(dir).multiplyScalar(1.35);
        label.scale.setScalar(0.5);
        this.triadScene.add(label);
      }
    }

    // ----- controls

    setUpControls() {
      const controls = new THREE.OrbitControls(this.camera, this.renderer.domElement);
      controls.enableDamping = false;
      controls.screenSpacePanning = true;
      controls.zoomToCursor = true;
      if (this.dimension === 2) {
        controls.enableRotate = false;
        controls.mouseButtons = { LEFT: THREE.MOUSE.PAN, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN };
        controls.touches = { ONE: THREE.TOUCH.PAN, TWO: THREE.TOUCH.DOLLY_PAN };
      }
      controls.addEventListener("change", () => this.requestRender());
      controls.addEventListener("start", () => { this.moved = true; });
      this.controls = controls;
      this.resize();
      this.resetView();

      const scrubber = $("scrubber");
      scrubber.max = String(this.times.length - 1);
      scrubber.addEventListener("input", () => { this.pause(); this.showFrame(Number(scrubber.value)); });
      $("play").addEventListener("click", () => (this.playing ? this.pause() : this.play()));
      $("first").addEventListener("click", () => { this.pause(); this.showFrame(0); });
      $("last").addEventListener("click", () => { this.pause(); this.showFrame(this.times.length - 1); });
      $("back").addEventListener("click", () => this.step(-1));
      $("forward").addEventListener("click", () => this.step(1));
      $("reset").addEventListener("click", () => this.resetView());

      const speed = $("speed");
      for (const s of SPEEDS) {
        const o = document.createElement("option");
        o.value = String(s); o.textContent = `${s}×`;
        speed.appendChild(o);
      }
      speed.value = "1";
      speed.addEventListener("change", () => { this.speed = Number(speed.value); this.anchor(); });

      const colorBy = $("color-by");
      const names = this.fieldNames();
      const options = (this.runs.length > 1 ? ["run"] : []).concat(names);
      if (!options.length) options.push("run");
      for (const n of options) {
        const o = document.createElement("option");
        o.value = n; o.textContent = n === "run" ? "run colour" : n;
        colorBy.appendChild(o);
      }
      colorBy.value = this.colorBy;
      colorBy.addEventListener("change", () => { this.colorBy = colorBy.value; this.showFrame(this.index); });

      $("follow-box").hidden = !this.relative;
      $("follow").checked = this.follow;
      $("follow").addEventListener("change", (ev) => { this.follow = ev.target.checked; this.resetView(); });

      document.addEventListener("keydown", (ev) => {
        if (ev.target instanceof HTMLSelectElement || ev.ctrlKey || ev.metaKey || ev.altKey) return;
        const big = ev.shiftKey ? 10 : 1;
        if (ev.key === " " || ev.key === "k") { ev.preventDefault(); this.playing ? this.pause() : this.play(); }
        else if (ev.key === "ArrowRight" || ev.key === ".") { ev.preventDefault(); this.step(big); }
        else if (ev.key === "ArrowLeft" || ev.key === ",") { ev.preventDefault(); this.step(-big); }
        else if (ev.key === "Home") { ev.preventDefault(); this.pause(); this.showFrame(0); }
        else if (ev.key === "End") { ev.preventDefault(); this.pause(); this.showFrame(this.times.length - 1); }
        else if (ev.key === "r") this.resetView();
      });
      this.renderer.domElement.addEventListener("pointermove", (ev) => this.hover(ev));
      this.renderer.domElement.addEventListener("pointerleave", () => { $("tooltip").hidden = true; });
      this.makeLegend();
    }

    makeLegend() {
      const legend = $("legend");
      legend.textContent = "";
      const row = (swatch, text, onClick) => {
        const div = document.createElement("div");
        div.className = "legend-row";
        div.appendChild(swatch);
        const span = document.createElement("span");
        span.textContent = text;
        div.appendChild(span);
        if (onClick) { div.classList.add("toggle"); div.addEventListener("click", () => onClick(div)); }
        legend.appendChild(div);
      };
      if (this.runs.length > 1) {
        for (const [r, run] of this.runs.entries()) {
          const sw = document.createElement("span");
          sw.className = "swatch"; sw.style.background = run.color;
          row(sw, run.name, (div) => {
            const g = this.drawn[r].group;
            g.visible = !g.visible;
            div.classList.toggle("off", !g.visible);
            this.requestRender();
          });
        }
      }
      const seen = new Set();
      for (const run of this.runs) for (const p of run.points) {
        if (seen.has(p.name)) continue;
        seen.add(p.name);
        const sw = document.createElement("span");
        sw.className = `glyph glyph-${p.kind}`; sw.style.color = p.color;
        row(sw, p.name);
      }
      for (const run of this.runs) for (const b of run.bodies) {
        if (seen.has(b.name)) continue;
        seen.add(b.name);
        const sw = document.createElement("span");
        sw.className = "glyph glyph-box";
        row(sw, b.name);
      }
      legend.hidden = !legend.childElementCount;
    }

    // ----- time

    step(n) {
      this.pause();
      this.showFrame(Math.min(Math.max(this.index + n, 0), this.times.length - 1));
    }

    play() {
      if (this.playing) return;
      if (this.index >= this.times.length - 1) this.showFrame(0);
      this.playing = true;
      $("play").innerHTML = PAUSE;
      $("play").title = "Pause (space)";
      this.anchor();
      this.fpsCount = 0; this.fpsSince = performance.now();
      this.requestRender();
    }

    pause() {
      if (!this.playing) return;
      this.playing = false;
      $("play").innerHTML = PLAY;
      $("play").title = "Play (space)";
      $("fps").textContent = "";
    }

    anchor() {                          // playing: simulated time = t0 + speed * (wall time - w0)
      this.t0 = this.times[this.index];
      this.w0 = performance.now();
    }

    advance(now) {
      const t = this.t0 + (this.speed * (now - this.w0)) / 1000;
      const end = this.times[this.times.length - 1];
      if (t >= end) { this.showFrame(this.times.length - 1); this.pause(); return; }
      const i = lastAtOrBefore(this.times, t);
      if (i !== this.index) this.showFrame(i);
      this.fpsCount++;
      if (now - this.fpsSince > 1000) {
        $("fps").textContent = `${Math.round((1000 * this.fpsCount) / (now - this.fpsSince))} fps`;
        this.fpsCount = 0; this.fpsSince = now;
      }
    }

    frameOf(run) { return lastAtOrBefore(run.time, this.times[this.index]); }

    showFrame(i) {
      this.index = i;
      const t = this.times[i];
      $("scrubber").value = String(i);
      $("time").textContent = `t = ${t.toFixed(Math.max(0, Math.min(6, -Math.floor(Math.log10(this.spacing()) + 1e-9))))} s`;
      $("frame").textContent = `frame ${i + 1} of ${this.times.length}`;
      for (const parts of this.drawn) {
        const run = this.runs[parts.run], f = this.frameOf(run);
        for (const l of parts.lines) this.updateLine(run, l, f);
        for (const p of parts.points) this.updatePoints(run, p, f);
        for (const b of parts.bodies) this.poseBody(run, b.b, b.object, f);
        if (parts.water) this.moveWater(parts.water, f);
      }
      if (this.follow && this.relative) this.followDriven();
      this.updateColorbar();
      this.drawSeries();
      this.requestRender();
    }

    spacing() {
      const n = this.times.length;
      return n > 1 ? Math.max((this.times[n - 1] - this.times[0]) / (n - 1), 1e-9) : 1;
    }

    followDriven() {
      const c = this.drivenCentre(this.relative.run, this.frameOf(this.relative.run));
      if (!c) return;
      const centre = new THREE.Vector3(...c);
      if (this.followed) {
        const shift = centre.clone().sub(new THREE.Vector3(...this.followed));
        this.camera.position.add(shift);
        this.controls.target.add(shift);
        this.controls.update();
      }
      this.followed = c;
      this.grids.relative.position.copy(centre);
    }

    fieldOf(line) { return line.fields.find((f) => f.name === this.colorBy); }

    updateLine(run, l, f) {
      const line = l.line, n = line.nodes, pos = l.positions, other = l.others, col = l.colors;
      const field = this.colorBy === "run" ? null : this.fieldOf(line);
      const runColor = srgb(run.color);      // the ribbon writes its colours as they are: sRGB
      const p = [0, 0, 0], q = [0, 0, 0];
      const cmap = this.colormap;
      const colorOf = (level, out, o) => {
        if (level === Q8_NOT_FINITE) { out[o] = out[o + 1] = out[o + 2] = 0.6; return; }
        const k = 3 * Math.round((level * 255) / FIELD_LEVELS);
        out[o] = cmap[k]; out[o + 1] = cmap[k + 1]; out[o + 2] = cmap[k + 2];
      };
      const c = [0, 0, 0, 0, 0, 0];
      for (let s = 0; s < l.segments; s++) {
        const a = s, b = (s + 1) % n;
        let pa = nodePosition(run, line.positions, n, f, a, p), pb = nodePosition(run, line.positions, n, f, b, q);
        if (!pa || !pb) pa = pb = pa || pb || [0, 0, 0];    // a node that is not finite: a segment of no length
        const o = 12 * s;
        for (let k = 0; k < 3; k++) {
          pos[o + k] = pos[o + 3 + k] = other[o + 6 + k] = other[o + 9 + k] = pa[k];
          pos[o + 6 + k] = pos[o + 9 + k] = other[o + k] = other[o + 3 + k] = pb[k];
        }
        if (!field) {
          c[0] = c[3] = runColor[0]; c[1] = c[4] = runColor[1]; c[2] = c[5] = runColor[2];
        } else if (field.per === "segment") {
          const per = field.values.length / run.frames;
          colorOf(field.values[f * per + s], c, 0);
          c[3] = c[0]; c[4] = c[1]; c[5] = c[2];
        } else {
          colorOf(field.values[f * n + a], c, 0);
          colorOf(field.values[f * n + b], c, 3);
        }
        for (let k = 0; k < 3; k++) {
          col[o + k] = col[o + 3 + k] = c[k];
          col[o + 6 + k] = col[o + 9 + k] = c[3 + k];
        }
      }
      const attributes = l.geometry.attributes;
      attributes.position.needsUpdate = attributes.other.needsUpdate = attributes.color.needsUpdate = true;
    }

    updatePoints(run, pp, f) {
      const p = pp.p, out = pp.positions, tmp = [0, 0, 0];
      for (let k = 0; k < pp.count; k++) {
        const r = p.positions ? nodePosition(run, p.positions, pp.count, f, k, tmp)
                              : nodePosition(run, run.lines[p.line].positions, run.lines[p.line].nodes, f, p.nodes[k], tmp);
        out[3 * k] = r ? r[0] : NaN; out[3 * k + 1] = r ? r[1] : NaN; out[3 * k + 2] = r ? r[2] : NaN;
      }
      pp.geometry.attributes.position.needsUpdate = true;
    }

    // ----- colour bar, series, summary

    fieldRange() {
      let low = Infinity, high = -Infinity, unit = "";
      for (const run of this.runs) for (const line of run.lines) {
        const f = this.fieldOf(line);
        if (!f) continue;
        low = Math.min(low, f.low); high = Math.max(high, f.high); unit = f.unit;
      }
      return { low, high, unit };
    }

    updateColorbar() {
      const bar = $("colorbar");
      if (this.colorBy === "run" || this.colorbarFor === this.colorBy) { bar.hidden = this.colorBy === "run"; return; }
      this.colorbarFor = this.colorBy;
      const { low, high, unit } = this.fieldRange();
      bar.hidden = false;
      const lo = low, hi = high;              // one range for every run (the packer makes it so)
      $("colorbar-title").textContent = `${this.colorBy} [${unit || "–"}]`;
      const canvas = $("colorbar-canvas"), g = canvas.getContext("2d");
      const h = canvas.height;
      for (let y = 0; y < h; y++) {
        const k = 3 * Math.round(255 * (1 - y / (h - 1)));
        g.fillStyle = `rgb(${255 * this.colormap[k]},${255 * this.colormap[k + 1]},${255 * this.colormap[k + 2]})`;
        g.fillRect(0, y, canvas.width, 1);
      }
      const ticks = $("colorbar-ticks");
      ticks.textContent = "";
      const n = 5;
      for (let i = 0; i < n; i++) {
        const v = hi - ((hi - lo) * i) / (n - 1);
        const div = document.createElement("div");
        div.textContent = format(v, unit);
        ticks.appendChild(div);
      }
    }

    setUpPanel() {
      const canvas = $("series");
      canvas.addEventListener("click", (ev) => {
        if (!this.seriesBox) return;
        const b = this.seriesBox, x = ev.offsetX;
        if (x < b.left || x > b.left + b.width) return;
        const t = b.t0 + ((x - b.left) / b.width) * (b.t1 - b.t0);
        this.pause();
        this.showFrame(lastAtOrBefore(this.times, t));
      });
      const table = $("summary");
      table.textContent = "";
      for (const run of this.runs) {
        const head = document.createElement("tr");
        const th = document.createElement("th");
        th.colSpan = 2; th.className = "run-head";
        th.innerHTML = "<span class='swatch'></span>";
        th.firstChild.style.background = run.color;
        th.appendChild(document.createTextNode(run.name));
        head.appendChild(th);
        if (this.runs.length > 1) table.appendChild(head);
        for (const [k, v] of run.summary) {
          const tr = document.createElement("tr");
          const a = document.createElement("th"), b = document.createElement("td");
          a.textContent = k; b.textContent = v;
          tr.append(a, b);
          table.appendChild(tr);
        }
        const tr = document.createElement("tr");
        const a = document.createElement("th"), b = document.createElement("td");
        a.textContent = "in this page";
        b.textContent = `${run.frames} of ${run.saved_frames} saved frames; positions within ` +
          `${format(run.quantisation.bound * 1000, "mm")} of the saved ones, fields within 1/${FIELD_LEVELS} of their range`;
        tr.append(a, b);
        table.appendChild(tr);
      }
      const units = [];
      for (const run of this.runs) for (const s of run.series) if (!units.includes(s.unit)) units.push(s.unit);
      this.seriesUnit = units[0];
      $("series-box").hidden = !units.length;
    }

    drawSeries() {
      const canvas = $("series");
      if (!canvas || $("series-box").hidden) return;
      const w = canvas.clientWidth, h = canvas.clientHeight, ratio = window.devicePixelRatio || 1;
      if (w === 0 || h === 0) return;
      if (canvas.width !== Math.round(w * ratio)) { canvas.width = Math.round(w * ratio); canvas.height = Math.round(h * ratio); }
      const g = canvas.getContext("2d");
      g.setTransform(ratio, 0, 0, ratio, 0, 0);
      g.clearRect(0, 0, w, h);
      const series = [];
      for (const run of this.runs) for (const [i, s] of run.series.entries())
        if (s.unit === this.seriesUnit) series.push({ run, s, dash: i });
      let lo = Infinity, hi = -Infinity;
      for (const { s } of series) for (const v of s.values) if (isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      if (!(lo <= hi)) return;
      if (lo === hi) { lo -= 1; hi += 1; }
      const t0 = this.times[0], t1 = this.times[this.times.length - 1] > t0 ? this.times[this.times.length - 1] : t0 + 1;
      const box = { left: 62, top: 22, width: w - 74, height: h - 44, t0, t1 };
      this.seriesBox = box;
      const X = (t) => box.left + ((t - t0) / (t1 - t0)) * box.width;
      const Y = (v) => box.top + (1 - (v - lo) / (hi - lo)) * box.height;
      g.font = "11px system-ui, sans-serif";
      g.fillStyle = "#444"; g.strokeStyle = "#ddd"; g.lineWidth = 1;
      const [factor, shownUnit] = scaled(this.seriesUnit, Math.max(Math.abs(lo), Math.abs(hi)));
      const vs = niceStep((hi - lo) * factor, 4) / factor;
      g.textAlign = "right"; g.textBaseline = "middle";
      for (let v = Math.ceil(lo / vs) * vs; v <= hi + vs / 1e6; v += vs) {
        g.beginPath(); g.moveTo(box.left, Y(v)); g.lineTo(box.left + box.width, Y(v)); g.stroke();
        g.fillText(format(v * factor, ""), box.left - 4, Y(v));
      }
      const ts = niceStep(t1 - t0, 8);
      g.textAlign = "center"; g.textBaseline = "top";
      for (let t = Math.ceil(t0 / ts) * ts; t <= t1 + ts / 1e6; t += ts) g.fillText(format(t, ""), X(t), box.top + box.height + 4);
      g.textAlign = "left"; g.textBaseline = "top";
      g.fillText(`[${shownUnit}]`, 4, 4);
      g.textAlign = "right";
      g.fillText("t [s]", w - 4, h - 14);
      let legendX = box.left;
      for (const { run, s, dash } of series) {
        g.strokeStyle = run.color; g.lineWidth = 1.5;
        g.setLineDash(dash ? [5, 3] : []);
        g.beginPath();
        let pen = false;
        for (let i = 0; i < s.values.length; i++) {
          const v = s.values[i];
          if (!isFinite(v)) { pen = false; continue; }
          const x = X(run.time[i]), y = Y(v);
          if (pen) g.lineTo(x, y); else g.moveTo(x, y);
          pen = true;
        }
        g.stroke();
        const label = (this.runs.length > 1 ? run.name + ": " : "") + s.name;
        g.beginPath(); g.moveTo(legendX, 10); g.lineTo(legendX + 18, 10); g.stroke();
        g.textAlign = "left"; g.textBaseline = "middle"; g.fillStyle = "#333";
        g.fillText(label, legendX + 22, 10);
        legendX += 30 + g.measureText(label).width;
      }
      g.setLineDash([]);
      const tc = this.times[this.index];
      g.strokeStyle = "#d62728"; g.lineWidth = 1.5;
      g.beginPath(); g.moveTo(X(tc), box.top); g.lineTo(X(tc), box.top + box.height); g.stroke();
      const values = series.map(({ run, s }) => s.values[lastAtOrBefore(run.time, tc)]);
      $("series-value").textContent = series.length
        ? `t = ${format(tc, "s")}: ` + series.map(({ run, s }, i) =>
          `${this.runs.length > 1 ? run.name + " " : ""}${s.name} ${format(values[i], s.unit)}`).join(", ")
        : "";
    }

    // ----- hover

    hover(ev) {
      if (ev.buttons) { $("tooltip").hidden = true; return; }
      const rect = this.renderer.domElement.getBoundingClientRect();
      const mx = ev.clientX - rect.left, my = ev.clientY - rect.top;
      let best = null, bestD = 12 * 12;
      const v = new THREE.Vector3(), tmp = [0, 0, 0];
      for (const parts of this.drawn) {
        if (!parts.group.visible) continue;
        const run = this.runs[parts.run], f = this.frameOf(run);
        for (const [li, l] of parts.lines.entries()) {
          const line = l.line;
          for (let k = 0; k < line.nodes; k++) {
            const p = nodePosition(run, line.positions, line.nodes, f, k, tmp);
            if (!p) continue;
            v.set(p[0], p[1], p[2]).project(this.camera);
            const sx = ((v.x + 1) / 2) * rect.width, sy = ((1 - v.y) / 2) * rect.height;
            const dd = (sx - mx) ** 2 + (sy - my) ** 2;
            if (dd < bestD && v.z < 1) { bestD = dd; best = { run, line, li, k, f, p: p.slice() }; }
          }
        }
      }
      const tip = $("tooltip");
      if (!best) { tip.hidden = true; return; }
      const { run, line, k, f, p } = best;
      const lines = [`${this.runs.length > 1 ? run.name + ", " : ""}${run.lines.length > 1 ? line.name + ", " : ""}node ${k}`,
        `(${p.slice(0, run.dimension).map((c) => c.toFixed(3)).join(", ")}) m`];
      for (const fl of line.fields) {
        const per = fl.values.length / run.frames;
        const index = fl.per === "segment" ? Math.min(k, per - 1) : k;
        const level = fl.values[f * per + index];
        const value = level === Q8_NOT_FINITE ? NaN : fl.low + ((fl.high - fl.low) * level) / FIELD_LEVELS;
        lines.push(`${fl.name} ${fl.per === "segment" ? `(segment ${index}) ` : ""}≈ ${format(value, fl.unit)}`);
      }
      tip.textContent = lines.join("\n");
      tip.hidden = false;
      tip.style.left = `${mx + 14}px`; tip.style.top = `${my + 10}px`;
    }

    // ----- drawing

    requestRender() {
      if (this.pending) return;
      this.pending = true;
      requestAnimationFrame((now) => this.frame(now));
    }

    frame(now) {
      this.pending = false;
      if (this.playing) this.advance(now);
      this.render();
      if (this.playing) this.requestRender();
    }

    render() {
      const r = this.renderer;
      r.setViewport(0, 0, this.width, this.height);
      r.setScissorTest(false);
      r.clear();
      r.render(this.scene, this.camera);
      const size = 84;                               // the axes triad, bottom left
      const dir = new THREE.Vector3().subVectors(this.camera.position, this.controls.target).normalize();
      this.triadCamera.position.copy(dir).multiplyScalar(4);
      this.triadCamera.up.copy(this.camera.up);
      this.triadCamera.lookAt(0, 0, 0);
      r.clearDepth();
      r.setViewport(4, 4, size, size);
      r.render(this.triadScene, this.triadCamera);
      hook.renders++;
      if (hook.firstFrameMs === null) {
        hook.firstFrameMs = performance.now();
        resolveReady();
      }
    }
  }

  // --------------------------------------------------------------------------------------- the hook

  function install(viewer) {
    hook.viewer = viewer;
    hook.state = () => ({
      frame: viewer.index, frames: viewer.times.length, t: viewer.times[viewer.index], playing: viewer.playing,
      speed: viewer.speed, colorBy: viewer.colorBy, renders: hook.renders, firstFrameMs: hook.firstFrameMs,
      decodeMs: hook.decodeMs,
      runFrames: viewer.runs.map((run) => viewer.frameOf(run)),
      camera: viewer.camera.position.toArray().concat([viewer.camera.zoom]),
    });
    hook.info = () => viewer.runs.map((run) => ({
      name: run.name, dimension: run.dimension, frames: run.frames, bound: run.quantisation.bound,
      lines: run.lines.map((l) => ({ name: l.name, nodes: l.nodes, closed: l.closed, fields: l.fields.map((f) => f.name) })),
      points: run.points.map((p) => p.name), bodies: run.bodies.map((b) => b.name),
      shapes: run.shapes.map((s) => s.name), water: !!run.water, seabed: !!run.seabed,
      series: run.series.map((s) => s.name),
    }));
    hook.setFrame = (i) => { viewer.pause(); viewer.showFrame(i); };
    hook.play = () => viewer.play();
    hook.pause = () => viewer.pause();
    hook.setSpeed = (s) => { viewer.speed = s; viewer.anchor(); };
    hook.positions = (r, l) => {
      const run = viewer.runs[r], line = run.lines[l], f = viewer.frameOf(run), out = [];
      for (let k = 0; k < line.nodes; k++) {
        const p = nodePosition(run, line.positions, line.nodes, f, k, [0, 0, 0]);
        out.push(p ? p.slice(0, run.dimension) : null);
      }
      return out;
    };
    hook.bodyPose = (r, b) => {
      const part = viewer.drawn[r].bodies[b].object;
      return { position: part.position.toArray(), quaternion: [part.quaternion.w, part.quaternion.x, part.quaternion.y, part.quaternion.z] };
    };
  }

  function fail(message) {
    hook.error = message;
    const box = $("failure");
    box.textContent = message;
    box.hidden = false;
    console.error(`ropesim view: ${message}`);
    rejectReady(new Error(message));
  }

  async function main() {
    const description = JSON.parse($("ropesim-description").textContent);
    document.title = description.runs.map((r) => r.name).join(" + ") + " · ropesim view";
    $("title").textContent = description.runs.map((r) => r.name).join(" + ");
    $("subtitle").textContent = description.runs.length === 1 ? description.runs[0].description : "";
    if (description.note) { $("note").textContent = description.note; $("note").hidden = false; }
    if (typeof DecompressionStream === "undefined") {
      fail("this browser cannot open the page's data (it lacks DecompressionStream): use a current Chrome, Edge, Firefox or Safari");
      return;
    }
    const probe = document.createElement("canvas");
    if (!(probe.getContext("webgl2") || probe.getContext("webgl"))) {
      fail("this browser has WebGL switched off, and the 3-D view needs it");
      return;
    }
    const t = performance.now();
    const buffer = await inflate($("ropesim-data").textContent);
    decodeAll(description, buffer);
    hook.decodeMs = performance.now() - t;
    install(new Viewer(description));
  }

  main().catch((err) => fail(`could not show the run: ${err && err.message ? err.message : err}`));
})();
