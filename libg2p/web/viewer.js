// The 3D view of summary.html. libg2p writes the object's geometry into the
// page as JSON (<script type="application/json" id="g2p-model">, written by
// libg2p/src/pipeline/summary_viewer.cpp) and inlines this file, bundled with
// three.js by esbuild at build time, so the page works from file:// offline.
// Without WebGL the section says so and the rest of the page is unchanged.
import {
  AmbientLight,
  Box3,
  BufferAttribute,
  BufferGeometry,
  Color,
  DirectionalLight,
  EdgesGeometry,
  Group,
  LineBasicMaterial,
  LineSegments,
  Mesh,
  MeshBasicMaterial,
  MeshLambertMaterial,
  PerspectiveCamera,
  Raycaster,
  Scene,
  SphereGeometry,
  Vector2,
  Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const BACKGROUND = 0xf4f4f4;

function decode(base64, Type) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return new Type(bytes.buffer, 0, bytes.byteLength / Type.BYTES_PER_ELEMENT);
}

// Positions come quantized to 16 bits over the mesh's bounds, indices as 16
// or 32 bits (summary_viewer.cpp's mesh_json).
function geometryOf(mesh) {
  const g = new BufferGeometry();
  const q = decode(mesh.positions, Uint16Array);
  const positions = new Float32Array(q.length);
  for (let i = 0; i < q.length; ++i) positions[i] = mesh.position_min[i % 3] + q[i] * mesh.position_step[i % 3];
  g.setAttribute('position', new BufferAttribute(positions, 3));
  g.setIndex(new BufferAttribute(decode(mesh.indices, mesh.index_bits === 16 ? Uint16Array : Uint32Array), 1));
  g.computeVertexNormals();
  return g;
}

// Per-face colours need a vertex per corner: made on first use only.
function lookGeometry(indexed, faceColorsBase64) {
  const g = indexed.toNonIndexed();
  const face = decode(faceColorsBase64, Uint8Array);
  const colors = new Float32Array(g.attributes.position.count * 3);
  const c = new Color();
  for (let f = 0; f < face.length / 3; ++f) {
    c.setRGB(face[3 * f] / 255, face[3 * f + 1] / 255, face[3 * f + 2] / 255, 'srgb');
    for (let k = 0; k < 3; ++k) colors.set([c.r, c.g, c.b], 9 * f + 3 * k);
  }
  g.setAttribute('color', new BufferAttribute(colors, 3));
  g.computeVertexNormals();
  return g;
}

function text(tag, content, className) {
  const e = document.createElement(tag);
  if (content !== undefined) e.textContent = content;
  if (className) e.className = className;
  return e;
}

// `digits` significant digits, without trailing zeros after the point (1100 stays 1100).
function fmt(v, digits = 4) {
  return String(Number(Number(v).toPrecision(digits)));
}

function webglAvailable() {
  try {
    const c = document.createElement('canvas');
    return !!(c.getContext('webgl2') || c.getContext('webgl'));
  } catch (e) {
    return false;
  }
}

function partDetails(p) {
  const rows = [
    ['class', p.material],
    ['structure', p.structure || '-'],
    ['wall thickness', p.structure === 'hollow' && p.wall_thickness_m > 0 ? `${fmt(p.wall_thickness_m * 1e3, 3)} mm`
      : p.structure === 'solid' ? '- (solid)' : '-'],
    ['density', p.density_kg_m3 ? `${fmt(p.density_kg_m3)} kg/m\u00b3` : '-'],
    ['mass', p.mass_kg !== undefined ? `${fmt(p.mass_kg)} kg` : '-'],
    ...(p.contents_mass_kg ? [['contents', `${fmt(p.contents_fill * 100, 3)} % full, ${fmt(p.contents_mass_kg)} kg`]] : []),
    ['volume', p.volume_m3 ? `${fmt(p.volume_m3 * 1e6)} cm\u00b3` : '-'],
  ];
  const box = document.createDocumentFragment();
  box.append(text('b', p.name));
  if (p.left_out) box.append(text('div', 'left out of the asset: ' + p.left_out, 'warn'));
  const table = document.createElement('table');
  for (const [k, v] of rows) {
    const tr = document.createElement('tr');
    tr.append(text('th', k), text('td', v));
    table.append(tr);
  }
  box.append(table);
  return box;
}

// Corrections (docs/pipeline.md#overrides): a form for the pinned part, the
// list of corrections so far, and a button that downloads them as the
// overrides file `g2p run/refine/properties/export --overrides` apply.
// `existing`: the part's correction so far, which the form starts from and replaces.
function correctionForm(p, index, classes, existing, onAdd) {
  const form = text('div', undefined, 'g2p-fix');
  form.append(text('b', 'Correct this part'));
  const field = (label, input) => {
    const l = document.createElement('label');
    l.append(label + ' ', input);
    form.append(l);
    return input;
  };
  const was = existing || {};
  const cls = document.createElement('select');
  cls.name = 'g2p-fix-class';
  cls.append(new Option(`${p.material} (as is)`, '', false, !was.class));  // also for a class outside the table
  for (const c of classes) {
    if (c.name !== p.material) cls.append(new Option(c.name, c.name, false, c.name === was.class));
  }
  field('class', cls);
  const structure = document.createElement('select');
  structure.name = 'g2p-fix-structure';
  for (const [v, t] of [['', 'as estimated'], ['solid', 'solid'], ['hollow', 'hollow']]) {
    structure.append(new Option(t, v, false, v === (was.structure || '')));
  }
  field('structure', structure);
  const wall = document.createElement('input');
  Object.assign(wall, { type: 'number', name: 'g2p-fix-wall-mm', min: '0', step: 'any', placeholder: 'as estimated' });
  if (was.wall_thickness_m) wall.value = String(was.wall_thickness_m * 1000);
  field('wall (mm)', wall);
  const density = document.createElement('input');
  Object.assign(density, { type: 'number', name: 'g2p-fix-density', min: '0', step: 'any', placeholder: 'as estimated' });
  if (was.density_kg_m3) density.value = String(was.density_kg_m3);
  field('density (kg/m\u00b3)', density);
  // Contents of a hollow part: the share of its cavity a fill takes, and the fill's density.
  const fill = document.createElement('input');
  Object.assign(fill, { type: 'number', name: 'g2p-fix-fill', min: '0', max: '100', step: 'any', placeholder: 'empty' });
  if (was.contents) fill.value = fmt(was.contents.fill * 100, 6);
  field('filled (%)', fill);
  const fillDensity = document.createElement('input');
  Object.assign(fillDensity, { type: 'number', name: 'g2p-fix-fill-density', min: '0', step: 'any', placeholder: 'water, 1000' });
  if (was.contents && was.contents.density_kg_m3) fillDensity.value = String(was.contents.density_kg_m3);
  field('fill density (kg/m\u00b3)', fillDensity);
  const error = text('div', '', 'warn');
  const add = text('button', 'Add correction', 'g2p-fix-add');
  add.type = 'button';
  add.addEventListener('click', () => {
    const entry = { part: p.part, was: { class: p.material, faces: p.faces } };
    if (cls.value) entry.class = cls.value;
    if (structure.value) entry.structure = structure.value;
    const mm = wall.value === '' ? null : Number(wall.value);
    const rho = density.value === '' ? null : Number(density.value);
    if (mm !== null && !(mm > 0 && mm <= 10000)) { error.textContent = 'the wall must be more than 0 and at most 10000 mm'; return; }
    if (mm !== null && structure.value === 'solid') { error.textContent = 'a solid part has no wall'; return; }
    if (rho !== null && !(rho > 0 && rho <= 30000)) { error.textContent = 'the density must be between 0 and 30000 kg/m\u00b3'; return; }
    const pct = fill.value === '' ? null : Number(fill.value);
    const fillRho = fillDensity.value === '' ? null : Number(fillDensity.value);
    if (pct !== null && !(pct >= 0 && pct <= 100)) { error.textContent = 'filled must be from 0 to 100 %'; return; }
    if (fillRho !== null && !(fillRho > 0 && fillRho <= 30000)) { error.textContent = 'the fill density must be between 0 and 30000 kg/m\u00b3'; return; }
    if (fillRho !== null && pct === null) { error.textContent = 'say how full the part is'; return; }
    if (pct > 0 && structure.value === 'solid') { error.textContent = 'a solid part holds no contents'; return; }
    if (pct > 0 && p.structure === 'solid' && structure.value !== 'hollow' && mm === null) {
      error.textContent = 'this part is solid: choose hollow to fill it'; return;
    }
    if (mm !== null) entry.wall_thickness_m = mm / 1000;
    if (rho !== null) entry.density_kg_m3 = rho;
    if (pct !== null) entry.contents = fillRho !== null ? { fill: pct / 100, density_kg_m3: fillRho } : { fill: pct / 100 };
    if (Object.keys(entry).length === 2) { error.textContent = 'nothing changed'; return; }
    error.textContent = '';
    onAdd(index, entry);
  });
  form.append(add, error);
  return form;
}

function start(section, model) {
  const box = section.querySelector('.g2p-canvas');
  const side = section.querySelector('.g2p-side');
  const renderer = new WebGLRenderer({ antialias: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
  renderer.setClearColor(BACKGROUND);
  box.append(renderer.domElement);

  const scene = new Scene();
  scene.add(new AmbientLight(0xffffff, 1.2));
  const sun = new DirectionalLight(0xffffff, 2.0);
  scene.add(sun);

  // libg2p's frame is +Z up.
  const camera = new PerspectiveCamera(35, 1, 1e-3, 1e3);
  camera.up.set(0, 0, 1);
  const controls = new OrbitControls(camera, renderer.domElement);

  const parts = model.parts.map((p, i) => {
    const group = new Group();
    const geometry = geometryOf(p.visual);
    const classMaterial = new MeshLambertMaterial({ color: new Color(p.color), flatShading: true, side: 2 });
    const mesh = new Mesh(geometry, classMaterial);
    mesh.userData.part = i;
    group.add(mesh);
    const hulls = new Group();
    for (const h of p.hulls) {
      const hg = geometryOf(h);
      hulls.add(new Mesh(hg, new MeshBasicMaterial({ color: 0x1f5fbf, transparent: true, opacity: 0.15, depthWrite: false })));
      hulls.add(new LineSegments(new EdgesGeometry(hg, 20), new LineBasicMaterial({ color: 0x1f3f8f })));
    }
    hulls.visible = false;
    group.add(hulls);
    scene.add(group);
    return { data: p, group, mesh, hulls, classMaterial, lookMaterial: null, lookGeometry: null };
  });

  const bounds = new Box3();
  for (const p of parts) bounds.expandByObject(p.mesh);
  const centre = bounds.getCenter(new Vector3());
  const radius = Math.max(bounds.getSize(new Vector3()).length() / 2, 1e-6);

  // The centre of mass: a ball and three axes through it, drawn over the object.
  const com = new Group();
  const ball = new Mesh(new SphereGeometry(radius * 0.04, 24, 12), new MeshBasicMaterial({ color: 0xd01010, depthTest: false }));
  const axes = new BufferGeometry();
  const a = radius * 0.3;
  axes.setAttribute('position', new BufferAttribute(new Float32Array([-a, 0, 0, a, 0, 0, 0, -a, 0, 0, a, 0, 0, 0, -a, 0, 0, a]), 3));
  com.add(ball, new LineSegments(axes, new LineBasicMaterial({ color: 0xd01010, depthTest: false })));
  for (const o of com.children) o.renderOrder = 10;
  com.position.fromArray(model.center_of_mass_m);
  com.visible = false;
  scene.add(com);

  camera.near = radius / 100;
  camera.far = radius * 100;
  camera.position.copy(centre).add(new Vector3(1.6, -2.2, 1.2).normalize().multiplyScalar(radius * 3.5));
  controls.target.copy(centre);
  controls.update();

  let pending = false;
  function render() {
    pending = false;
    sun.position.copy(camera.position).sub(controls.target).add(new Vector3(0, 0, radius));
    renderer.render(scene, camera);
  }
  function requestRender() {
    if (!pending) {
      pending = true;
      requestAnimationFrame(render);
    }
  }
  function resize() {
    const w = box.clientWidth;
    const h = box.clientHeight;
    renderer.setSize(w, h, true);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    render();
  }
  controls.addEventListener('change', requestRender);
  new ResizeObserver(resize).observe(box);

  // Controls: colour mode, hulls, centre of mass, one checkbox per part.
  const controlsBox = side.querySelector('.g2p-toggles');
  function toggle(label, checked, onChange, name) {
    const l = document.createElement('label');
    const input = document.createElement('input');
    input.type = 'checkbox';
    input.checked = checked;
    if (name) input.name = name;
    input.addEventListener('change', () => { onChange(input.checked); requestRender(); });
    l.append(input, ' ' + label);
    controlsBox.append(l);
    return input;
  }
  toggle("input's own look", false, (on) => {
    for (const p of parts) {
      if (on && !p.lookGeometry) {
        p.lookGeometry = lookGeometry(p.mesh.geometry, p.data.visual.look);
        p.lookMaterial = new MeshLambertMaterial({ vertexColors: true, side: 2 });
        p.classGeometry = p.mesh.geometry;
      }
      p.mesh.geometry = on ? p.lookGeometry : p.classGeometry || p.mesh.geometry;
      p.mesh.material = on ? p.lookMaterial : p.classMaterial;
    }
  }, 'look');
  toggle('collision hulls', false, (on) => { for (const p of parts) p.hulls.visible = on; }, 'hulls');
  toggle('centre of mass', false, (on) => { com.visible = on; }, 'com');

  const info = side.querySelector('.g2p-info');
  const list = side.querySelector('.g2p-parts');
  const fixesBox = side.querySelector('.g2p-fixes');
  const fixes = [];  // overrides entries, in the order they were made
  let objectFix = '';  // what the object is, when the person corrects it ("object" of the overrides file)
  let objectInput = null;
  let pinned = -1;
  let hovered = -1;
  function overridesFile() {
    return {
      format: 'g2p-overrides', version: 1, model: model.model || undefined, object: objectFix || undefined,
      faces_total: model.triangles, overrides: fixes,
    };
  }
  // What the object is: the identification, and a field to correct it with a kind of the object table.
  if (model.object) {
    const row = text('label', 'What it is: ', 'g2p-object-fix');
    const input = document.createElement('input');
    objectInput = input;
    input.setAttribute('list', 'g2p-kinds');
    input.value = model.object.kind === 'unknown' ? '' : model.object.kind;
    input.placeholder = 'unknown';
    const kinds = document.createElement('datalist');
    kinds.id = 'g2p-kinds';
    for (const k of model.object.kinds || []) kinds.append(new Option(k));
    input.addEventListener('change', () => {
      const v = input.value.trim().toLowerCase();
      const fix = v && v !== model.object.kind && (model.object.kinds || []).includes(v) ? v : '';
      input.setCustomValidity(v && !(model.object.kinds || []).includes(v) ? 'not a kind of the object table' : '');
      // Only a new value redraws the list: a second change event (on blur, as the person clicks the
      // download button) must not replace the button under the click.
      if (fix === objectFix) return;
      objectFix = fix;
      showFixes();
    });
    row.append(input, kinds);
    controlsBox.parentNode.insertBefore(row, controlsBox);
  }
  function showFixes() {
    fixesBox.replaceChildren();
    if (!fixes.length && !objectFix) return;
    fixesBox.append(text('b', `Corrections (${fixes.length + (objectFix ? 1 : 0)})`));
    const ol = document.createElement('ol');
    if (objectFix) ol.append(text('li', `the object is a ${objectFix} (was ${model.object.kind})`));
    for (const f of fixes) {
      const what = ['class', 'structure', 'wall_thickness_m', 'density_kg_m3', 'contents'].filter((k) => k in f)
        .map((k) => (k === 'wall_thickness_m' ? `wall ${fmt(f[k] * 1e3, 3)} mm` : k === 'density_kg_m3'
          ? `${fmt(f[k])} kg/m\u00b3` : k === 'contents' ? (f[k].fill > 0 ? `${fmt(f[k].fill * 100, 3)} % full` +
            ` (${fmt(f[k].density_kg_m3 || 1000)} kg/m\u00b3)` : 'empty') : f[k]));
      ol.append(text('li', `${parts[f.part].data.name} (${f.was.class}): ${what.join(', ')}`));
    }
    const download = text('button', 'Download overrides.json', 'g2p-fix-download');
    download.type = 'button';
    download.addEventListener('click', () => {
      const blob = new Blob([JSON.stringify(overridesFile(), null, 1) + '\n'], { type: 'application/json' });
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = 'overrides.json';
      document.body.append(a);
      a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(a.href), 1000);
    });
    const clear = text('button', 'Clear', 'g2p-fix-clear');
    clear.type = 'button';
    clear.addEventListener('click', () => {
      fixes.length = 0;
      objectFix = '';
      if (objectInput) objectInput.value = model.object.kind === 'unknown' ? '' : model.object.kind;
      parts.forEach((p, k) => {
        p.classMaterial.color.set(p.data.color);
        list.children[k].querySelector('.sw').style.background = p.data.color;
      });
      showFixes();
      requestRender();
    });
    fixesBox.append(ol, download, ' ', clear,
      text('p', 'Apply them with g2p export THIS_FOLDER --overrides overrides.json -o NEW_FOLDER (or g2p run ' +
        'MODEL --overrides overrides.json -o NEW_FOLDER); the stages after the change run again.', 'note'));
  }
  function addFix(i, entry) {
    for (let k = fixes.length - 1; k >= 0; --k) if (fixes[k].part === entry.part) fixes.splice(k, 1);  // the latest stands
    fixes.push(entry);
    const c = entry.class && model.classes.find((x) => x.name === entry.class);
    parts[i].classMaterial.color.set(c ? c.color : parts[i].data.color);
    list.children[i].querySelector('.sw').style.background = c ? c.color : parts[i].data.color;
    showFixes();
    requestRender();
  }
  function show(i) {
    info.replaceChildren(i >= 0 ? partDetails(parts[i].data) : text('span', 'Hover over or click a part for its details.'));
    if (i >= 0 && i === pinned && model.classes) {
      const existing = fixes.find((f) => f.part === parts[i].data.part);
      info.append(correctionForm(parts[i].data, i, model.classes, existing, addFix));
    }
    parts.forEach((p, k) => {
      p.classMaterial.emissive.setHex(k === i ? 0x404040 : 0);
      if (p.lookMaterial) p.lookMaterial.emissive.setHex(k === i ? 0x404040 : 0);
      list.children[k].classList.toggle('sel', k === i);
    });
    requestRender();
  }
  parts.forEach((p, i) => {
    const li = document.createElement('li');
    const input = document.createElement('input');
    input.type = 'checkbox';
    input.checked = true;
    input.name = 'part' + i;
    input.addEventListener('change', () => { p.group.visible = input.checked; requestRender(); });
    const sw = text('span', '', 'sw');
    sw.style.background = p.data.color;
    const name = text('span', `${p.data.name}${p.data.left_out ? ' (left out)' : ''}`);
    name.addEventListener('click', () => { pinned = pinned === i ? -1 : i; show(pinned); });
    const l = document.createElement('label');
    l.append(input, sw);
    li.append(l, name);
    list.append(li);
  });

  const raycaster = new Raycaster();
  const pointer = new Vector2();
  function pick(event) {
    const r = renderer.domElement.getBoundingClientRect();
    pointer.set(((event.clientX - r.left) / r.width) * 2 - 1, -((event.clientY - r.top) / r.height) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    const visible = parts.filter((p) => p.group.visible).map((p) => p.mesh);
    const hit = raycaster.intersectObjects(visible, false)[0];
    return hit ? hit.object.userData.part : -1;
  }
  let moveQueued = null;
  renderer.domElement.addEventListener('pointermove', (event) => {
    if (moveQueued) { moveQueued = event; return; }
    moveQueued = event;
    requestAnimationFrame(() => {
      const i = pick(moveQueued);
      moveQueued = null;
      if (pinned < 0 && i !== hovered) { hovered = i; show(i); }
    });
  });
  let down = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', (e) => {
    if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;  // a drag, not a click
    pinned = pick(e);
    show(pinned);
  });
  show(-1);
  resize();
  section.dataset.state = 'ready';
  // For scripts and tests: redraw now, the WebGL context.
  window.g2pViewer = { parts: parts.length, render, gl: () => renderer.getContext(), overrides: overridesFile };
}

function main() {
  const section = document.getElementById('g2p-3d');
  const data = document.getElementById('g2p-model');
  if (!section || !data) return;
  const status = section.querySelector('.g2p-status');
  if (!webglAvailable()) {
    section.dataset.state = 'no-webgl';
    status.textContent = 'This browser has no WebGL, so the 3D view is off; the rest of the page is complete.';
    return;
  }
  try {
    section.querySelector('.g2p-viewer').hidden = false;
    start(section, JSON.parse(data.textContent));
    status.remove();
  } catch (e) {
    section.dataset.state = 'error';
    status.textContent = `The 3D view failed (${e.message}); the rest of the page is complete.`;
    throw e;
  }
}

main();
