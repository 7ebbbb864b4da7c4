// The stage-stepper page written by `focal steps` (data contract: docs/steps-format.md).
// Vanilla JS, no network: it opens from file://, reads window.FOCAL_STEPS (set by
// steps_data.js) and shows images with <img> only (never getImageData: a canvas that drew a
// file:// image is tainted and reading it throws).
//
// Stable hooks for tests (tests/browser/steps_page_test.mjs) and other tools:
//   #messages .message[data-kind]      every problem the page found ("error" | "warning" | "info")
//   #stage-list li[data-stage-id]      one per stage, in display order; .selected on the current
//   #stage-view[data-stage-id]         the stage shown; #stage-title, #stage-paper, #stage-text
//   #image-picker button[data-image-index]   when a stage has several images
//   #stage-image[data-file][data-scale][data-loaded="true"|"error"]   the stage's image
//   #stage-overlay                     SVG over it: .shape, .point, .crosshair (frame coordinates)
//   #zoom-level[data-zoom]             the integer zoom (screen pixels per frame pixel)
//   #hover-xy[data-x][data-y]          the frame pixel under the mouse
//   #compare-result, #compare-reference, #compare-difference   the side-by-side images
//   #probe-panel[data-probe-index][data-probe-x][data-probe-y]   the selected probe (-1: none)
//   #probe-xy[data-x][data-y]          the probed pixel
//   #probe-exact[data-exact="true"|"false"][data-clicked-x][data-clicked-y]
//   #probe-command                     probe_command with X,Y filled in for the clicked pixel
//   #probe-rgba[data-rgba], #probe-reference-rgba[data-rgba]   JSON arrays, the exact numbers
//   #probe-fragments (table), #probe-method (tree of the method record)
(function () {
  'use strict';

  // Stage groups in the order a frame runs them; unknown groups go just before "result".
  const kGroupOrder = ['raster', 'targets', 'gather', 'multiview', 'multilayer', 'accum', 'result'];
  const kMaxZoom = 64;
  const kSvgNs = 'http://www.w3.org/2000/svg';

  const state = {
    data: null,
    stages: [],         // stages in display order (grouped)
    stagePos: -1,       // index into state.stages
    imageChoice: {},    // stage id -> selected image index
    probes: [],         // sorted by (y, x)
    probePos: -1,       // index into state.probes
    clicked: null,      // {x, y}: the frame pixel the user clicked (null after keyboard moves)
    zoom: 1,
    stacks: [],         // every image stack on the page: {img, svg, record, role}
  };

  const $ = (id) => document.getElementById(id);

  function el(tag, attrs, children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === 'text') node.textContent = v;
      else if (k === 'class') node.className = v;
      else node.setAttribute(k, v);
    }
    for (const c of children || []) node.append(c);
    return node;
  }

  // A visible message instead of a console error: the user of a file:// page has no console open.
  const shownMessages = new Set();
  function showMessage(text, kind = 'error') {
    if (shownMessages.has(text)) return;
    shownMessages.add(text);
    $('messages').append(el('div', { class: 'message ' + kind, 'data-kind': kind, text }));
  }

  const isNum = (v) => typeof v === 'number' && Number.isFinite(v);
  const isObj = (v) => v !== null && typeof v === 'object' && !Array.isArray(v);

  // Numbers for reading: integers as they are, others to 6 significant digits. The data
  // attributes keep the exact values.
  function fmt(v) {
    if (v === null || v === undefined) return '—';
    if (typeof v === 'object') return JSON.stringify(v);
    if (typeof v !== 'number') return String(v);
    if (Number.isInteger(v)) return String(v);
    return String(Number(v.toPrecision(6)));
  }

  // ---- Data checks: problems become messages, and the page shows what it can. ----

  function checkImage(rec, where) {
    if (!isObj(rec) || typeof rec.file !== 'string') {
      showMessage(`${where}: an image without a "file"; it is skipped.`);
      return null;
    }
    const scale = rec.scale === undefined ? 1 : rec.scale;
    if (!isNum(scale) || scale <= 0) {
      showMessage(`${where}: image ${rec.file} has a bad "scale" (${rec.scale}); using 1.`, 'warning');
    }
    return {
      name: typeof rec.name === 'string' ? rec.name : rec.file,
      file: rec.file,
      width: isNum(rec.width) ? rec.width : null,   // null: taken from the loaded image
      height: isNum(rec.height) ? rec.height : null,
      scale: isNum(scale) && scale > 0 ? scale : 1,
      caption: typeof rec.caption === 'string' ? rec.caption : '',
    };
  }

  function checkStage(s, i) {
    if (!isObj(s)) {
      showMessage(`stages[${i}] is not an object; it is skipped.`);
      return null;
    }
    const id = typeof s.id === 'string' && s.id ? s.id : `stage-${i}`;
    if (id !== s.id) showMessage(`stages[${i}] has no "id"; calling it ${id}.`, 'warning');
    const list = (key) => {
      if (s[key] === undefined) return [];
      if (Array.isArray(s[key])) return s[key];
      showMessage(`stage ${id}: "${key}" is not a list; ignored.`, 'warning');
      return [];
    };
    return {
      id,
      group: typeof s.group === 'string' && s.group ? s.group : id.split('.')[0],
      title: typeof s.title === 'string' && s.title ? s.title : id,
      paper: typeof s.paper === 'string' ? s.paper : '',
      text: typeof s.text === 'string' ? s.text : '',
      ms: isNum(s.ms) ? s.ms : null,
      counts: isObj(s.counts) ? s.counts : {},
      images: list('images').map((r, k) => checkImage(r, `stage ${id} image ${k}`)).filter(Boolean),
      tables: list('tables'),
      plots: list('plots'),
    };
  }

  const isRgba = (v) => Array.isArray(v) && v.length === 4 && v.every(isNum);

  function checkProbes(probes) {
    if (probes === undefined) return [];
    if (!Array.isArray(probes)) {
      showMessage('"probes" is not a list; no probed pixels to show.');
      return [];
    }
    const good = probes.filter((p, i) => {
      const ok = isObj(p) && Number.isInteger(p.x) && Number.isInteger(p.y);
      if (!ok) showMessage(`probes[${i}] has no integer x, y; it is skipped.`);
      return ok;
    });
    // The contract sorts by (y, x); sort anyway so stepping is in reading order regardless.
    return good.slice().sort((a, b) => a.y - b.y || a.x - b.x);
  }

  function groupRank(group) {
    const k = kGroupOrder.indexOf(group);
    return k >= 0 ? k : kGroupOrder.length - 1.5;
  }

  // Returns false when there is nothing to show.
  function loadData() {
    const d = window.FOCAL_STEPS;
    if (window.FOCAL_STEPS_LOAD_FAILED || d === undefined) {
      showMessage('steps_data.js is missing or could not be read. Open index.html inside the folder ' +
                  'that `focal steps ... -o DIR` wrote (it holds steps_data.js and images/).');
      return false;
    }
    if (!isObj(d)) {
      showMessage('steps_data.js does not set window.FOCAL_STEPS to an object; the folder is damaged.');
      return false;
    }
    if (d.format_version !== 1) {
      showMessage(`This folder has format_version ${d.format_version}; this page reads version 1. ` +
                  'Some parts may not show.', 'warning');
    }
    if (!Array.isArray(d.stages) || d.stages.length === 0) {
      showMessage('FOCAL_STEPS has no stages; there is nothing to step through.');
      return false;
    }
    const stages = d.stages.map(checkStage).filter(Boolean);
    const ids = new Set();
    for (const s of stages) {
      if (ids.has(s.id)) showMessage(`Two stages are called ${s.id}.`, 'warning');
      ids.add(s.id);
    }
    // Group, keeping the run order inside a group (Array.prototype.sort is stable).
    state.stages = stages.map((s, i) => ({ s, i }))
      .sort((a, b) => groupRank(a.s.group) - groupRank(b.s.group) || a.i - b.i)
      .map((e) => e.s);
    let width = d.width, height = d.height;
    if (!(Number.isInteger(width) && width > 0 && Number.isInteger(height) && height > 0)) {
      const first = stages.flatMap((s) => s.images).find((r) => r.width && r.height && r.scale === 1);
      width = first ? first.width : 1;
      height = first ? first.height : 1;
      showMessage(`FOCAL_STEPS has no valid width/height; using ${width}×${height}.`, 'warning');
    }
    state.data = Object.assign({}, d, { width, height });
    state.probes = checkProbes(d.probes);
    if (state.probes.length === 0) showMessage('This folder has no probed pixels.', 'info');
    return state.stages.length > 0;
  }

  // ---- Header and stage list ----

  function renderHeader() {
    const d = state.data;
    const method = typeof d.method === 'string' ? d.method : '?';
    const scene = typeof d.scene === 'string' ? d.scene : '?';
    $('frame-title').textContent = `focal steps — ${scene}, ${method}, ${d.width}×${d.height}`;
    $('frame-command').textContent = typeof d.command === 'string' ? d.command : '';
    document.title = `focal steps: ${scene} (${method})`;
  }

  function renderStageList() {
    const list = $('stage-list');
    list.textContent = '';
    let group = null;
    state.stages.forEach((s, pos) => {
      if (s.group !== group) {
        group = s.group;
        list.append(el('li', { class: 'group', text: group }));
      }
      const li = el('li', { 'data-stage-id': s.id, 'data-group': s.group, text: s.title });
      li.addEventListener('click', () => selectStage(pos));
      list.append(li);
    });
  }

  // ---- Image stacks: an <img> at an integer zoom with an SVG overlay in frame coordinates ----

  function makeStack(record, role, ids) {
    const img = el('img', { alt: record.name, 'data-file': record.file, 'data-scale': String(record.scale) });
    const svg = document.createElementNS(kSvgNs, 'svg');
    svg.setAttribute('class', 'overlay');
    svg.setAttribute('preserveAspectRatio', 'none');
    if (ids) {
      img.id = ids.img;
      svg.id = ids.svg;
    }
    const root = el('div', { class: 'stack' }, [img, svg]);
    const stack = { root, img, svg, record, role };
    img.addEventListener('load', () => {
      img.setAttribute('data-loaded', 'true');
      sizeStack(stack);
      drawOverlay(stack);
    });
    img.addEventListener('error', () => {
      img.setAttribute('data-loaded', 'error');
      img.hidden = true;
      svg.setAttribute('hidden', '');
      const cmd = typeof state.data.command === 'string' ? ` Re-run: ${state.data.command}` : '';
      root.append(el('div', { class: 'image-error',
        text: `Could not load ${record.file} (missing, or not an image). The folder may be incomplete.${cmd}` }));
      showMessage(`Could not load ${record.file}.`);
    });
    root.addEventListener('mousemove', (ev) => showHover(stack, ev));
    root.addEventListener('mouseleave', () => showHover(stack, null));
    root.addEventListener('click', (ev) => clickPixel(stack, ev));
    img.src = record.file;
    state.stacks.push(stack);
    return stack;
  }

  // The frame pixels an image covers: its own size times its scale (frame pixels per image pixel).
  function frameExtent(stack) {
    const r = stack.record;
    const w = r.width || stack.img.naturalWidth || state.data.width;
    const h = r.height || stack.img.naturalHeight || state.data.height;
    return { w: w * r.scale, h: h * r.scale };
  }

  function sizeStack(stack) {
    const { w, h } = frameExtent(stack);
    const z = state.zoom;
    stack.img.style.width = `${w * z}px`;
    stack.img.style.height = `${h * z}px`;
    stack.svg.setAttribute('width', String(w * z));
    stack.svg.setAttribute('height', String(h * z));
    stack.svg.setAttribute('viewBox', `0 0 ${w} ${h}`);
  }

  // Mouse position -> frame pixel. The image shows each frame pixel as zoom x zoom screen
  // pixels whatever its scale, so the mapping is the same for every image.
  function framePixel(stack, ev) {
    const rect = stack.img.getBoundingClientRect();
    const { w, h } = frameExtent(stack);
    const fx = Math.floor((ev.clientX - rect.left) / state.zoom);
    const fy = Math.floor((ev.clientY - rect.top) / state.zoom);
    if (fx < 0 || fy < 0 || fx >= Math.min(w, state.data.width) || fy >= Math.min(h, state.data.height)) {
      return null;
    }
    return { x: fx, y: fy };
  }

  function showHover(stack, ev) {
    const out = $('hover-xy');
    const p = ev ? framePixel(stack, ev) : null;
    out.textContent = p ? `${p.x}, ${p.y}` : '—';
    out.setAttribute('data-x', p ? String(p.x) : '');
    out.setAttribute('data-y', p ? String(p.y) : '');
  }

  // ---- Overlays: the probe's shapes for the current stage, and a crosshair on the probed pixel ----

  function svgEl(tag, attrs) {
    const node = document.createElementNS(kSvgNs, tag);
    for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, String(v));
    return node;
  }

  const isPoint = (p) => Array.isArray(p) && p.length >= 2 && isNum(p[0]) && isNum(p[1]);

  function shapeNode(shape, z) {
    const label = typeof shape.label === 'string' ? shape.label : '';
    let node = null;
    if (shape.kind === 'polyline' && Array.isArray(shape.points) && shape.points.every(isPoint)) {
      node = svgEl('polyline', { class: 'shape', points: shape.points.map((p) => `${p[0]},${p[1]}`).join(' ') });
    } else if (shape.kind === 'point' && isPoint(shape.at)) {
      node = svgEl('circle', { class: 'point', cx: shape.at[0], cy: shape.at[1], r: 3 / z });
    } else if (shape.kind === 'circle' && isPoint(shape.at) && isNum(shape.r)) {
      node = svgEl('circle', { class: 'shape', cx: shape.at[0], cy: shape.at[1], r: Math.abs(shape.r) });
    } else {
      showMessage(`A probe has a shape the page cannot draw (kind ${JSON.stringify(shape.kind)}).`, 'warning');
      return null;
    }
    if (label) {
      const title = svgEl('title', {});
      title.textContent = label;
      node.append(title);
    }
    return node;
  }

  function shapeBelongs(shape, stageId) {
    return isObj(shape) && Array.isArray(shape.stages) &&
      (shape.stages.includes('*') || shape.stages.includes(stageId));
  }

  function crosshair(svg, p, extent) {
    // Lines stop short of the pixel so its colour stays visible; a square outlines it.
    const cx = p.x + 0.5, cy = p.y + 0.5, gap = 1.5;
    const lines = [[0, cy, p.x - gap + 1, cy], [p.x + gap, cy, extent.w, cy],
                   [cx, 0, cx, p.y - gap + 1], [cx, p.y + gap, cx, extent.h]];
    for (const [x1, y1, x2, y2] of lines) svg.append(svgEl('line', { class: 'crosshair', x1, y1, x2, y2 }));
    svg.append(svgEl('rect', { class: 'crosshair', x: p.x, y: p.y, width: 1, height: 1 }));
  }

  function drawOverlay(stack) {
    const svg = stack.svg;
    svg.textContent = '';
    const probe = state.probes[state.probePos];
    if (!probe) return;
    const stage = state.stages[state.stagePos];
    if (stack.role === 'stage' && stage && Array.isArray(probe.draw)) {
      for (const shape of probe.draw) {
        if (!shapeBelongs(shape, stage.id)) continue;
        const node = shapeNode(shape, state.zoom);
        if (node) svg.append(node);
      }
    }
    crosshair(svg, probe, frameExtent(stack));
  }

  function redrawAll() {
    state.stacks = state.stacks.filter((s) => s.root.isConnected);
    for (const s of state.stacks) {
      sizeStack(s);
      drawOverlay(s);
    }
  }

  // ---- Zoom: integer factors only, so every frame pixel is a whole square of screen pixels ----

  function setZoom(z) {
    state.zoom = Math.min(kMaxZoom, Math.max(1, Math.round(z)));
    const out = $('zoom-level');
    out.textContent = `${state.zoom}×`;
    out.setAttribute('data-zoom', String(state.zoom));
    redrawAll();
  }

  function fitZoom() {
    const view = $('stage-view');
    const availW = Math.max(1, view.clientWidth - 4);
    const availH = Math.max(1, window.innerHeight * 0.7 - 4);
    setZoom(Math.max(1, Math.floor(Math.min(availW / state.data.width, availH / state.data.height))));
  }

  // ---- One stage ----

  function selectStage(pos) {
    if (pos < 0 || pos >= state.stages.length) return;
    state.stagePos = pos;
    const stage = state.stages[pos];
    document.querySelectorAll('#stage-list li[data-stage-id]').forEach((li, k) => {
      const on = k === pos;
      li.classList.toggle('selected', on);
      if (on) {
        li.setAttribute('aria-current', 'step');
        li.scrollIntoView({ block: 'nearest' });
      } else {
        li.removeAttribute('aria-current');
      }
    });
    $('stage-view').setAttribute('data-stage-id', stage.id);
    $('stage-title').textContent = stage.title;
    $('stage-paper').textContent = stage.paper;
    $('stage-text').textContent = stage.text;
    $('stage-time').textContent = stage.ms === null ? 'not timed' : `${fmt(stage.ms)} ms`;
    renderCounts(stage.counts);
    renderImagePicker(stage);
    renderStageImage(stage);
    guard(`stage ${stage.id}: tables`, () => renderTables(stage));
    guard(`stage ${stage.id}: plots`, () => renderPlots(stage));
    redrawAll();
  }

  function renderCounts(counts) {
    const table = $('stage-counts');
    table.textContent = '';
    for (const [k, v] of Object.entries(counts)) {
      table.append(el('tr', {}, [el('th', { text: k }), el('td', { text: fmt(v) })]));
    }
  }

  function renderImagePicker(stage) {
    const picker = $('image-picker');
    picker.textContent = '';
    if (stage.images.length < 2) return;
    const current = state.imageChoice[stage.id] || 0;
    stage.images.forEach((rec, k) => {
      const b = el('button', { type: 'button', 'data-image-index': String(k), text: rec.name });
      if (k === current) b.classList.add('selected');
      b.addEventListener('click', () => showImage(stage, k));
      picker.append(b);
    });
  }

  function showImage(stage, k) {
    state.imageChoice[stage.id] = k;
    renderImagePicker(stage);
    renderStageImage(stage);
    redrawAll();
  }

  function renderStageImage(stage) {
    const viewport = $('stage-viewport');
    viewport.textContent = '';
    const caption = $('image-caption');
    if (stage.images.length === 0) {
      viewport.hidden = true;
      caption.textContent = 'This stage has no images.';
      return;
    }
    viewport.hidden = false;
    const rec = stage.images[state.imageChoice[stage.id] || 0] || stage.images[0];
    const stack = makeStack(rec, 'stage', { img: 'stage-image', svg: 'stage-overlay' });
    viewport.append(stack.root);
    sizeStack(stack);
    const scaleNote = rec.scale !== 1 ? ` (${rec.scale}×${rec.scale} frame pixels per image pixel)` : '';
    caption.textContent = `${rec.name}: ${rec.caption}${scaleNote}`;
  }

  // ---- Tables and plots ----

  function renderTables(stage) {
    const box = $('stage-tables');
    box.textContent = '';
    stage.tables.forEach((t, k) => {
      if (!isObj(t) || !Array.isArray(t.rows)) {
        box.append(el('p', { class: 'image-error', text: `Table ${k} of this stage is malformed.` }));
        return;
      }
      const columns = Array.isArray(t.columns) ? t.columns : [];
      const table = el('table', { class: 'data', 'data-table-name': String(t.name || k) });
      table.append(el('caption', { text: String(t.name || '') }));
      table.append(el('tr', {}, columns.map((c) => el('th', { text: String(c) }))));
      for (const row of t.rows) {
        const cells = Array.isArray(row) ? row : [row];
        table.append(el('tr', {}, cells.map((c) => el('td', { text: fmt(c) }))));
      }
      box.append(table);
    });
  }

  function plotRange(range, values) {
    if (Array.isArray(range) && range.length === 2 && isNum(range[0]) && isNum(range[1]) && range[0] !== range[1]) {
      return range;
    }
    const lo = Math.min(...values), hi = Math.max(...values);
    return lo < hi ? [lo, hi] : [lo - 1, hi + 1];
  }

  function renderPlots(stage) {
    const box = $('stage-plots');
    box.textContent = '';
    stage.plots.forEach((plot, k) => {
      const name = isObj(plot) && plot.name ? String(plot.name) : `plot ${k}`;
      if (!isObj(plot) || plot.kind !== 'points' || !Array.isArray(plot.points) || !plot.points.every(isPoint)) {
        box.append(el('p', { class: 'image-error', text: `${name}: not a points plot this page can draw.` }));
        return;
      }
      box.append(el('div', { text: name }));
      box.append(drawPointsPlot(plot));
    });
  }

  function drawPointsPlot(plot) {
    const size = 300, pad = 34, dpr = window.devicePixelRatio || 1;
    const canvas = el('canvas', { class: 'plot', 'data-plot-name': String(plot.name || '') });
    canvas.width = size * dpr;
    canvas.height = size * dpr;
    canvas.style.width = `${size}px`;
    canvas.style.height = `${size}px`;
    const g = canvas.getContext('2d');
    g.scale(dpr, dpr);
    const xr = plotRange(plot.x_range, plot.points.map((p) => p[0]));
    const yr = plotRange(plot.y_range, plot.points.map((p) => p[1]));
    const inner = size - 2 * pad;
    const px = (x) => pad + ((x - xr[0]) / (xr[1] - xr[0])) * inner;
    const py = (y) => size - pad - ((y - yr[0]) / (yr[1] - yr[0])) * inner; // y up
    // Axes box and range labels
    g.strokeStyle = '#999';
    g.strokeRect(pad, pad, inner, inner);
    g.fillStyle = '#444';
    g.font = '11px sans-serif';
    g.textAlign = 'center';
    g.fillText(fmt(xr[0]), pad, size - pad + 14);
    g.fillText(fmt(xr[1]), size - pad, size - pad + 14);
    g.fillText(String(plot.x_label || ''), size / 2, size - 6);
    g.textAlign = 'right';
    g.fillText(fmt(yr[0]), pad - 4, size - pad);
    g.fillText(fmt(yr[1]), pad - 4, pad + 8);
    g.save();
    g.translate(12, size / 2);
    g.rotate(-Math.PI / 2);
    g.textAlign = 'center';
    g.fillText(String(plot.y_label || ''), 0, 0);
    g.restore();
    // Points, with their labels when there are few enough to read
    const labels = Array.isArray(plot.labels) && plot.points.length <= 64 ? plot.labels : null;
    g.textAlign = 'left';
    plot.points.forEach((p, i) => {
      g.fillStyle = '#0a62c9';
      g.beginPath();
      g.arc(px(p[0]), py(p[1]), 3, 0, 2 * Math.PI);
      g.fill();
      if (labels && labels[i] !== undefined) {
        g.fillStyle = '#444';
        g.fillText(String(labels[i]), px(p[0]) + 4, py(p[1]) - 4);
      }
    });
    return canvas;
  }

  // ---- Side by side: result | reference | difference ----

  function renderCompare() {
    const c = state.data.compare;
    const box = $('compare-images');
    box.textContent = '';
    if (!isObj(c)) {
      $('compare-caption').textContent = 'This folder has no comparison with the reference.';
      return;
    }
    const size = { width: state.data.width, height: state.data.height, scale: 1, caption: '' };
    const samples = isNum(c.reference_samples) ? ` (accum, ${c.reference_samples} samples)` : '';
    const panels = [['result', 'result'], ['reference', 'reference' + samples], ['difference', 'difference']];
    for (const [key, title] of panels) {
      const fig = el('figure', {}, [el('figcaption', { text: title })]);
      if (typeof c[key] === 'string') {
        const view = el('div', { class: 'viewport' });
        const stack = makeStack(Object.assign({ name: key, file: c[key] }, size), 'compare',
                                { img: `compare-${key}`, svg: `compare-${key}-overlay` });
        view.append(stack.root);
        fig.append(view);
      } else {
        fig.append(el('div', { class: 'image-error', text: `compare.${key} is missing.` }));
      }
      box.append(fig);
    }
    syncScrolling(Array.from(box.querySelectorAll('.viewport')));
    const metrics = [isNum(c.psnr_db) ? `PSNR ${fmt(c.psnr_db)} dB` : null,
                     isNum(c.ssim) ? `SSIM ${fmt(c.ssim)}` : null].filter(Boolean).join(', ');
    $('compare-caption').textContent = [metrics, typeof c.caption === 'string' ? c.caption : '']
      .filter(Boolean).join(' — ');
  }

  // Scrolling one compare view scrolls the others to the same place.
  function syncScrolling(views) {
    let syncing = false;
    for (const v of views) {
      v.addEventListener('scroll', () => {
        if (syncing) return;
        syncing = true;
        for (const w of views) {
          if (w !== v) {
            w.scrollLeft = v.scrollLeft;
            w.scrollTop = v.scrollTop;
          }
        }
        syncing = false;
      });
    }
  }

  // Scrolls a stack's viewport so the frame pixel p is in view (centred when it was not).
  function revealPixel(stack, p) {
    const view = stack.root.parentElement;
    if (!view || !view.classList.contains('viewport')) return;
    const z = state.zoom;
    const x = (p.x + 0.5) * z, y = (p.y + 0.5) * z;
    const visible = x >= view.scrollLeft && x < view.scrollLeft + view.clientWidth &&
                    y >= view.scrollTop && y < view.scrollTop + view.clientHeight;
    if (visible) return;
    view.scrollLeft = x - view.clientWidth / 2;
    view.scrollTop = y - view.clientHeight / 2;
  }

  // ---- Probes ----

  function nearestProbe(p) {
    let best = -1, bestD = Infinity;
    state.probes.forEach((q, i) => {
      const d = (q.x - p.x) ** 2 + (q.y - p.y) ** 2;
      if (d < bestD) { best = i; bestD = d; } // strict: ties keep the first in (y, x) order
    });
    return best;
  }

  function clickPixel(stack, ev) {
    const p = framePixel(stack, ev);
    if (!p) return;
    if (state.probes.length === 0) {
      showMessage('This folder has no probed pixels; use the probe command (see README) to probe one.', 'info');
      return;
    }
    selectProbe(nearestProbe(p), p);
  }

  function selectProbe(pos, clicked) {
    if (pos < 0 || pos >= state.probes.length) return;
    state.probePos = pos;
    state.clicked = clicked || null;
    guard('probe', renderProbe);
    redrawAll();
    for (const stack of state.stacks) revealPixel(stack, state.probes[pos]);
  }

  function fillProbeCommand(x, y) {
    const cmd = state.data.probe_command;
    if (typeof cmd !== 'string' || !cmd.includes('X,Y')) return null;
    return cmd.replace('X,Y', `${x},${y}`);
  }

  // Linear light -> an sRGB CSS colour for a swatch (IEC 61966-2-1), alpha as opacity.
  function swatchColour(rgba) {
    const enc = (v) => {
      const c = Math.min(1, Math.max(0, v));
      return Math.round(255 * (c <= 0.0031308 ? 12.92 * c : 1.055 * Math.pow(c, 1 / 2.4) - 0.055));
    };
    return `rgba(${enc(rgba[0])}, ${enc(rgba[1])}, ${enc(rgba[2])}, ${Math.min(1, Math.max(0, rgba[3]))})`;
  }

  function showRgba(valueId, swatchId, rgba) {
    const out = $(valueId), sw = $(swatchId);
    sw.textContent = '';
    if (!isRgba(rgba)) {
      out.textContent = 'missing';
      out.setAttribute('data-rgba', '');
      return;
    }
    out.textContent = rgba.map(fmt).join(', ');
    out.setAttribute('data-rgba', JSON.stringify(rgba));
    sw.append(el('span', { style: `background: ${swatchColour(rgba)}` }));
  }

  function renderProbe() {
    const probe = state.probes[state.probePos];
    const panel = $('probe-panel');
    panel.setAttribute('data-probe-index', String(state.probePos));
    panel.setAttribute('data-probe-x', String(probe.x));
    panel.setAttribute('data-probe-y', String(probe.y));
    $('probe-empty').hidden = true;
    $('probe-body').hidden = false;
    const xy = $('probe-xy');
    xy.textContent = `(${probe.x}, ${probe.y})`;
    xy.setAttribute('data-x', String(probe.x));
    xy.setAttribute('data-y', String(probe.y));
    $('probe-position').textContent = `— probe ${state.probePos + 1} of ${state.probes.length}`;
    renderExactness(probe);
    showRgba('probe-rgba', 'probe-swatch', probe.rgba);
    showRgba('probe-reference-rgba', 'probe-reference-swatch', probe.reference_rgba);
    renderFragments(probe.fragments);
    const tree = $('probe-method');
    tree.textContent = '';
    if (probe.method === undefined) tree.textContent = 'no method record';
    else tree.append(jsonNode('method', probe.method, 0));
  }

  function renderExactness(probe) {
    const box = $('probe-exact');
    const c = state.clicked;
    const exact = !c || (c.x === probe.x && c.y === probe.y);
    box.setAttribute('data-exact', String(exact));
    box.setAttribute('data-clicked-x', c ? String(c.x) : '');
    box.setAttribute('data-clicked-y', c ? String(c.y) : '');
    box.classList.toggle('inexact', !exact);
    box.textContent = exact ? '' :
      `You clicked (${c.x}, ${c.y}), which was not probed; this is the nearest probed pixel.`;
    $('probe-command-label').textContent = exact ? 'the same from the command line:' : 'probe the clicked pixel:';
    const cmd = fillProbeCommand(c ? c.x : probe.x, c ? c.y : probe.y);
    $('probe-command').textContent = cmd || '(this folder gives no probe_command)';
  }

  function renderFragments(fragments) {
    const table = $('probe-fragments');
    table.textContent = '';
    if (!Array.isArray(fragments) || fragments.length === 0) {
      table.append(el('tr', {}, [el('td', { text: 'no fragments' })]));
      return;
    }
    table.className = 'data';
    table.append(el('tr', {}, ['#', 'depth', 'primitive', 'rgba', ''].map((h) => el('th', { text: h }))));
    fragments.forEach((f, i) => {
      const ok = isObj(f);
      const rgba = ok && isRgba(f.rgba) ? f.rgba : null;
      const sw = el('span', { class: 'swatch' });
      if (rgba) sw.append(el('span', { style: `background: ${swatchColour(rgba)}` }));
      table.append(el('tr', {}, [
        el('td', { text: String(i) }),
        el('td', { text: ok ? fmt(f.depth) : '?' }),
        el('td', { text: ok ? fmt(f.primitive) : '?' }),
        el('td', { text: rgba ? rgba.map(fmt).join(', ') : '?' }),
        el('td', {}, [sw]),
      ]));
    });
  }

  // Any JSON as a collapsible tree; short lists of numbers inline, lists of flat records as tables.
  function jsonNode(key, value, depth) {
    const label = el('span', { class: 'key', text: key });
    if (value === null || typeof value !== 'object') {
      return el('div', { class: 'leaf' }, [label, `: ${fmt(value)}`]);
    }
    if (Array.isArray(value) && value.length <= 16 && value.every((v) => v === null || typeof v !== 'object')) {
      return el('div', { class: 'leaf' }, [label, `: [${value.map(fmt).join(', ')}]`]);
    }
    if (Object.keys(value).length === 0) {
      return el('div', { class: 'leaf' }, [label, Array.isArray(value) ? ': [] (empty)' : ': {} (empty)']);
    }
    const details = el('details', depth < 2 ? { open: '' } : {});
    const size = Array.isArray(value) ? `[${value.length}]` : `{${Object.keys(value).length}}`;
    details.append(el('summary', {}, [label, ` ${size}`]));
    if (Array.isArray(value) && value.length > 0 && value.every(isFlatRecord)) {
      details.append(recordTable(value));
      return details;
    }
    for (const [k, v] of Object.entries(value)) details.append(jsonNode(k, v, depth + 1));
    return details;
  }

  const isShortList = (v) => Array.isArray(v) && v.length <= 8 && v.every((x) => x === null || typeof x !== 'object');
  const isFlatRecord = (r) => isObj(r) && Object.values(r).every((v) => v === null || typeof v !== 'object' || isShortList(v));

  function recordTable(records) {
    const keys = [];
    for (const r of records) for (const k of Object.keys(r)) if (!keys.includes(k)) keys.push(k);
    const table = el('table', { class: 'data' });
    table.append(el('tr', {}, ['#', ...keys].map((k) => el('th', { text: k }))));
    records.forEach((r, i) => {
      const cell = (v) => el('td', { text: Array.isArray(v) ? v.map(fmt).join(', ') : fmt(v) });
      table.append(el('tr', {}, [el('td', { text: String(i) }), ...keys.map((k) => cell(r[k]))]));
    });
    return table;
  }

  // ---- Keyboard ----

  function onKey(ev) {
    if (ev.ctrlKey || ev.metaKey || ev.altKey) return;
    const tag = ev.target && ev.target.tagName;
    if (tag === 'INPUT' || tag === 'TEXTAREA' || tag === 'SELECT') return;
    const moves = {
      ArrowRight: () => selectStage(state.stagePos + 1), j: () => selectStage(state.stagePos + 1),
      ArrowLeft: () => selectStage(state.stagePos - 1), k: () => selectStage(state.stagePos - 1),
      ArrowDown: () => stepProbe(+1), n: () => stepProbe(+1),
      ArrowUp: () => stepProbe(-1), p: () => stepProbe(-1),
      i: nextImage,
      '+': () => setZoom(state.zoom + 1), '=': () => setZoom(state.zoom + 1),
      '-': () => setZoom(state.zoom - 1), '0': fitZoom,
    };
    const action = moves[ev.key];
    if (!action) return;
    ev.preventDefault(); // arrows would scroll the page
    guard(`key ${ev.key}`, action);
  }

  // Cycles through the current stage's images (layers, levels), as the picker's buttons do.
  function nextImage() {
    const stage = state.stages[state.stagePos];
    if (!stage || stage.images.length < 2) return;
    showImage(stage, ((state.imageChoice[stage.id] || 0) + 1) % stage.images.length);
  }

  function stepProbe(delta) {
    if (state.probes.length === 0) return;
    // With nothing selected, "next" starts at the first probe and "previous" at the last.
    const next = state.probePos < 0 ? (delta > 0 ? 0 : state.probes.length - 1) : state.probePos + delta;
    selectProbe(Math.min(state.probes.length - 1, Math.max(0, next)), null);
  }

  // Runs f; a failure (a bug, or data the checks missed) becomes a visible message.
  function guard(what, f) {
    try {
      f();
    } catch (e) {
      showMessage(`The page could not show ${what}: ${e && e.message ? e.message : e}`);
    }
  }

  function main() {
    if (!loadData()) return;
    renderHeader();
    renderStageList();
    guard('the comparison', renderCompare);
    document.addEventListener('keydown', onKey);
    $('zoom-in').addEventListener('click', () => setZoom(state.zoom + 1));
    $('zoom-out').addEventListener('click', () => setZoom(state.zoom - 1));
    $('zoom-fit').addEventListener('click', fitZoom);
    selectStage(0);
    fitZoom();
  }

  guard('this folder', main);
})();
