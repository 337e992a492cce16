// SPDX-License-Identifier: GPL-2.0-or-later
// i20 console: plain JavaScript, no libraries. Every value shown comes from the server's
// /api, which answers through the same use cases as the i20 commands; nothing here decides
// whether a value is safe.
'use strict';

const $ = (id) => document.getElementById(id);
const SVG = 'http://www.w3.org/2000/svg';
const WINDOW_S = 60;       // seconds of live samples the plot shows
const MAX_SAMPLES = 6000;  // kept for the CSV export (10 minutes at 10 samples/s)

function el(tag, attrs, text) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
}

async function api(path, body, headers) {
  const options = body === undefined ? {} : { method: 'POST', body, headers: { 'Content-Type': 'text/plain', ...headers } };
  const res = await fetch(path, options);
  const type = res.headers.get('Content-Type') || '';
  const data = type.startsWith('application/json') ? await res.json() : { outcome: 'error', lines: [{ label: 'error', message: await res.text() }] };
  return { status: res.status, data };
}

function failureText(data) {
  if (data.lines) return data.lines.map((l) => l.label + ': ' + l.message).join('; ');
  return data.summary || data.error || data.outcome;
}

// ------------------------------------------------------------------ overview
async function loadOverview() {
  const { status, data } = await api('/api/overview');
  const table = $('identity');
  table.textContent = '';
  if (status !== 200) {
    table.append(el('tr', {}, failureText(data)));
    return;
  }
  $('card').textContent = data.card + (data.simulator ? ' (simulated card)' : '');
  const r = data.readings;
  const rows = [
    ['Card', data.card_name + ' unit ' + data.unit_number],
    ['Firmware', 'SWREVISION ' + data.swrevision],
    ['Working map', data.working_map_confirmed ? 'confirmed for this firmware' : 'NOT confirmed for this firmware (NV parameters only; run i20 discover)'],
    ['Bus voltage', r.busv_v === null ? 'unknown' : r.busv_v.toFixed(1) + ' V'],
    ['Temperature', r.temperature_c === null ? 'unknown' : r.temperature_c.toFixed(1) + ' degC'],
    ['Target', data.target],
  ];
  for (const [k, v] of rows) {
    const tr = el('tr');
    tr.append(el('th', {}, k), el('td', { 'data-key': k }, v));
    table.append(tr);
  }
  showOverviewFaults(data.fault, data.status);
  $('overview-pending').textContent = data.pending.length ? data.pending.join(', ') + ' (a reset makes them live)' : 'none';
}

// A latched fault must not read like no fault: it stands out, says which bits, and leads to
// the Faults page where each is explained.
function showOverviewFaults(fault, status) {
  const target = $('overview-faults');
  target.textContent = '';
  const latched = fault.bits.length > 0;
  const box = el('div', { class: 'result ' + (latched ? 'alert' : 'ok'), id: 'overview-fault-state', 'data-latched': String(latched) });
  box.append(el('p', {}, fault.title));
  if (latched) {
    const link = el('a', { href: '#faults', id: 'overview-faults-link' }, 'Explain and clear them on the Faults page');
    link.addEventListener('click', (event) => { event.preventDefault(); show('faults'); });
    box.append(link);
  }
  target.append(box, el('p', {}, status.title));
}

// The server judges what a reset would make live by the write rules and refuses an unsafe
// one (nothing but reads sent); the question here only guards against a stray click.
async function resetCard() {
  if (!window.confirm('Reset the 8I20? Its NV values become the working values.')) return;
  const { status, data } = await api('/api/reset', '');
  const box = el('div', { class: 'result ' + (status === 200 ? 'ok' : 'refused') });
  box.append(el('p', {}, data.reset ? 'Reset; now live: ' + (data.made_live.join(', ') || 'nothing was pending')
    : data.findings ? 'Refused: no reset was sent (only reads)' : failureText(data)));
  for (const f of data.findings || []) box.append(el('p', { class: f.severity }, f.severity + ': ' + f.message));
  $('reset-result').textContent = '';
  $('reset-result').append(box);
  await loadOverview();
}

// ------------------------------------------------------------------ parameters
async function loadParams() {
  forgetPreview();  // the boxes are emptied: what was previewed is no longer on the page
  const { status, data } = await api('/api/params');
  const body = $('params').querySelector('tbody');
  body.textContent = '';
  if (status !== 200) {
    body.append(el('tr', {}, failureText(data)));
    return;
  }
  for (const p of data.params) {
    const tr = el('tr', { 'data-name': p.name });
    const value = el('td', { class: p.fact ? 'value' : 'value unknown' }, p.text);
    const note = el('td');
    if (p.not_live_until_reset) note.append(el('span', { class: 'badge' }, 'not live until reset'));
    if (p.guard) note.append(el('span', { title: p.guard }, ' guarded'));
    const edit = el('td');
    if (p.writable && p.fact) {
      const input = el('input', { name: p.name, placeholder: p.unit || 'value' });
      input.addEventListener('input', previewOutdated);
      edit.append(input);
    }
    tr.append(el('td', { title: p.description }, p.name), value, el('td', {}, p.min + ' … ' + p.max),
      el('td', {}, p.twin || ''), note, edit);
    body.append(tr);
  }
}

function assignments() {
  const lines = [];
  for (const input of $('params').querySelectorAll('input')) {
    const v = input.value.trim();
    if (v !== '') lines.push(input.name + '=' + v);
  }
  return lines.join('\n');
}

function showRun(target, status, data) {
  target.textContent = '';
  const ok = status === 200 && data.ok !== false;
  const box = el('div', { class: 'result ' + (ok ? 'ok' : 'refused'), id: 'run-outcome', 'data-outcome': data.outcome });
  box.append(el('p', {}, data.summary || failureText(data)));
  for (const f of data.findings || [])
    box.append(el('p', { class: f.severity }, f.severity + ': ' + (f.key ? f.key + ': ' : '') + f.message + ' [' + f.rule + ']'));
  const cells = data.cell_states && data.cell_states.length ? data.cell_states : null;
  const steps = data.plan ? data.plan.steps : [];
  if (cells || steps.length) {
    const t = el('table', { class: 'grid' });
    if (cells) {
      t.append(el('tr', {}, ''));
      t.lastChild.append(el('th', {}, 'Cell'), el('th', {}, 'Now on the card'), el('th', {}, 'Outcome'));
      for (const c of cells) {
        const tr = el('tr', { 'data-cell': c.cell });
        tr.append(el('td', {}, c.cell), el('td', {}, c.now), el('td', {}, c.state));
        t.append(tr);
      }
    } else {
      t.append(el('tr'));
      t.lastChild.append(el('th', {}, 'Cell'), el('th', {}, 'Card holds'), el('th', {}, 'Would write'));
      for (const s of steps) {
        const tr = el('tr');
        tr.append(el('td', {}, s.cell), el('td', {}, s.card_text), el('td', {}, s.profile_text));
        t.append(tr);
      }
    }
    box.append(t);
  }
  if (data.not_live && data.not_live.length) box.append(el('p', {}, 'Not live until reset: ' + data.not_live.join(', ')));
  target.append(box);
  return ok;
}

// Apply writes exactly what the last preview showed: the lines previewed and the id the
// server gave that preview. An edit after it disables Apply until the values are previewed
// again; the server refuses an apply whose lines or planned writes differ from its preview.
let previewed = null;  // { lines, id }

function forgetPreview() {
  previewed = null;
  $('apply').disabled = true;
}

function showOutdated() {
  const note = $('preview-outdated');
  note.textContent = 'Edited since the preview: Preview again before Apply (Apply writes only what a preview showed).';
  note.classList.remove('hidden');
}

function previewOutdated() {
  if (!previewed) return;
  forgetPreview();
  showOutdated();
}

async function preview() {
  forgetPreview();
  $('preview-outdated').classList.add('hidden');
  const lines = assignments();
  const { status, data } = await api('/api/preview', lines);
  showRun($('change-result'), status, data);
  if (!data.preview_id) return;
  // A box edited while the preview was on its way: what it showed is not on the page any more.
  if (assignments() !== lines) return showOutdated();
  previewed = { lines, id: data.preview_id };
  $('apply').disabled = false;
}

async function apply() {
  if (!previewed || assignments() !== previewed.lines) return previewOutdated();
  const { lines, id } = previewed;
  forgetPreview();
  const { status, data } = await api('/api/apply', lines, { 'I20-Preview': id });
  showRun($('change-result'), status, data);
  await loadParams();
}

// ------------------------------------------------------------------ faults
// Text from the server in `i20 faults`'s words; a `command` or button name in backticks is
// shown as code.
function words(tag, text, attrs) {
  const e = el(tag, attrs || {});
  text.split('`').forEach((part, i) => e.append(i % 2 ? el('code', {}, part) : document.createTextNode(part)));
  return e;
}

function list(box, title, items, ordered) {
  if (!items || !items.length) return;
  box.append(el('p', {}, title));
  const l = el(ordered ? 'ol' : 'ul');
  for (const item of items) l.append(words('li', item));
  box.append(l);
}

function bitBox(bit) {
  const box = el('div', { class: 'bit ' + bit.severity });
  box.append(el('h3', {}, bit.heading));
  if (bit.hal_pin) box.append(el('p', { class: 'hint' }, 'LinuxCNC HAL pin: ' + bit.hal_pin));
  box.append(words('p', bit.meaning));
  if (bit.now) box.append(words('p', 'Now: ' + bit.now, { class: 'now' }));
  list(box, 'Likely causes:', bit.causes, false);
  list(box, 'Check:', bit.checks, true);
  return box;
}

function showReport(titleEl, bitsEl, report) {
  titleEl.textContent = report.title;
  bitsEl.textContent = '';
  if (report.fault_output) bitsEl.append(words('p', report.fault_output, { class: 'fault-output' }));
  for (const b of report.bits) bitsEl.append(bitBox(b));
  if (report.notes && report.notes.length) list(bitsEl, 'About FAULT:', report.notes, false);
}

async function loadFaults() {
  const { status, data } = await api('/api/faults');
  if (status !== 200) {
    $('fault-title').textContent = failureText(data);
    return;
  }
  showReport($('fault-title'), $('fault-bits'), data.explained.fault);
  showReport($('status-title'), $('status-bits'), data.explained.status);
}

// What the clear did, as `i20 clear-faults` says it: cleared, still latched and why.
function showCleared(box, said) {
  box.append(el('p', {}, said.summary));
  if (said.cleared.length) box.append(el('p', {}, 'Cleared: ' + said.cleared.join(', ')));
  for (const bit of said.remaining) {
    const b = el('div', { class: 'bit fault' });
    b.append(el('h3', {}, 'Remains latched: ' + bit.heading), words('p', bit.meaning), words('p', 'Why: ' + bit.why));
    list(b, 'Check:', bit.checks, true);
    box.append(b);
  }
  box.append(words('p', said.fault_output));
  if (said.advice) box.append(el('p', {}, said.advice));
}

async function clearFaults() {
  const { status, data } = await api('/api/clear-faults', '');
  const ok = status === 200 && data.outcome === 'done';
  const box = el('div', { class: 'result ' + (ok ? 'ok' : 'refused'), id: 'clear-outcome', 'data-outcome': data.outcome });
  if (data.explained) showCleared(box, data.explained);
  else box.append(el('p', {}, failureText(data)));
  $('clear-result').textContent = '';
  $('clear-result').append(box);
  await loadFaults();
}

// ------------------------------------------------------------------ live
const samples = [];
let socket = null;

function connectLive() {
  if (socket) return;
  socket = new WebSocket('ws://' + location.host + '/api/live');
  socket.onopen = () => { $('live-state').textContent = 'live'; };
  socket.onclose = () => { $('live-state').textContent = 'disconnected'; socket = null; };
  socket.onmessage = (event) => {
    const s = JSON.parse(event.data);
    s.received = Date.now();
    samples.push(s);
    if (samples.length > MAX_SAMPLES) samples.shift();
    showSample(s);
    drawPlot();
  };
}

function showSample(s) {
  $('live-count').textContent = String(samples.length);
  if (s.error) {
    $('live-state').textContent = s.error;
    return;
  }
  $('live-state').textContent = 'live';
  $('live-busv').textContent = s.busv === null ? 'unknown' : s.busv.toFixed(1) + ' V';
  $('live-temp').textContent = s.temperature === null ? 'unknown' : s.temperature.toFixed(1) + ' degC';
  $('live-fault').textContent = s.fault + (s.fault_bits.length ? ' ' + s.fault_bits.join(', ') : '');
  $('live-status').textContent = s.status + (s.status_bits.length ? ' ' + s.status_bits.join(', ') : '');
}

function svg(tag, attrs) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
}

// Two bands, one above the other, each with its own scale, axis labels and legend: scaled
// into one area, a steady bus voltage and a steady temperature both sit in the middle and
// one line hides the other.
const PLOT = { left: 60, width: 680 };
const BANDS = {
  busv: { top: 30, height: 105, color: '#1565c0', unit: 'V', label: 'Bus voltage' },
  temperature: { top: 175, height: 105, color: '#c62828', unit: 'degC', label: 'Temperature' },
};

function plotX(now, t) {
  return PLOT.left + (PLOT.width * (WINDOW_S * 1000 - (now - t))) / (WINDOW_S * 1000);
}

// One series in its band: frame, legend, min/max labels and its line.
function series(plot, points, key) {
  const band = BANDS[key];
  plot.append(svg('rect', { x: PLOT.left, y: band.top, width: PLOT.width, height: band.height, fill: 'none', stroke: '#ccc' }));
  const values = points.filter((p) => p[key] !== null && p[key] !== undefined);
  const legend = svg('text', { x: PLOT.left, y: band.top - 6, fill: band.color, 'font-size': 12, class: 'legend-' + key });
  const last = values.length ? values[values.length - 1][key].toFixed(1) + ' ' + band.unit : 'unknown';
  legend.textContent = band.label + ' (' + band.unit + '): ' + last;
  plot.append(legend);
  if (!values.length) return;
  let lo = Math.min(...values.map((p) => p[key]));
  let hi = Math.max(...values.map((p) => p[key]));
  if (hi - lo < 1) { lo -= 0.5; hi += 0.5; }
  const now = points[points.length - 1].t;
  const y = (v) => band.top + band.height - 5 - ((band.height - 10) * (v - lo)) / (hi - lo);
  const line = values.map((p) => plotX(now, p.t).toFixed(1) + ',' + y(p[key]).toFixed(1)).join(' ');
  plot.append(svg('polyline', { points: line, fill: 'none', stroke: band.color, 'stroke-width': 1.5, class: 'series-' + key }));
  for (const v of [lo, hi]) {
    const label = svg('text', { x: PLOT.left - 4, y: y(v) + 4, fill: band.color, 'font-size': 11, 'text-anchor': 'end' });
    label.textContent = v.toFixed(1);
    plot.append(label);
  }
}

function drawPlot() {
  const plot = $('plot');
  const now = samples.length ? samples[samples.length - 1].t : 0;
  const points = samples.filter((s) => !s.error && now - s.t <= WINDOW_S * 1000);
  plot.textContent = '';
  // A red band across both plots wherever FAULT was non-zero.
  for (const p of points) {
    if (p.fault === '0x0000') continue;
    plot.append(svg('rect', { x: plotX(now, p.t) - 1, y: 30, width: 2, height: 250, fill: '#fcc' }));
  }
  series(plot, points, 'busv');
  series(plot, points, 'temperature');
  const caption = svg('text', { x: PLOT.left, y: 296, 'font-size': 11, fill: '#555' });
  caption.textContent = 'last ' + WINDOW_S + ' s, each line on its own scale; FAULT set: red band';
  plot.append(caption);
  plot.setAttribute('data-points', String(points.length));
}

function exportCsv() {
  const rows = ['time_ms,busv_v,temperature_c,fault,status,fault_bits,status_bits,error'];
  const q = (s) => '"' + String(s).replace(/"/g, '""') + '"';
  for (const s of samples)
    rows.push([s.t, s.busv ?? '', s.temperature ?? '', s.fault ?? '', s.status ?? '',
      q((s.fault_bits || []).join(' ')), q((s.status_bits || []).join(' ')), q(s.error || '')].join(','));
  const url = URL.createObjectURL(new Blob([rows.join('\n') + '\n'], { type: 'text/csv' }));
  const a = el('a', { href: url, download: 'i20-live.csv' });
  document.body.append(a);
  a.click();
  a.remove();
  URL.revokeObjectURL(url);
}

// ------------------------------------------------------------------ pages
const loaders = { overview: loadOverview, params: loadParams, faults: loadFaults, live: connectLive };

function show(page) {
  for (const tab of document.querySelectorAll('.tab')) tab.classList.toggle('active', tab.dataset.page === page);
  for (const section of document.querySelectorAll('.page')) section.classList.toggle('hidden', section.id !== 'page-' + page);
  loaders[page]();
}

document.addEventListener('DOMContentLoaded', () => {
  for (const tab of document.querySelectorAll('.tab')) tab.addEventListener('click', () => show(tab.dataset.page));
  $('reset').addEventListener('click', resetCard);
  $('preview').addEventListener('click', preview);
  $('apply').addEventListener('click', apply);
  $('reload-params').addEventListener('click', loadParams);
  $('clear-faults').addEventListener('click', clearFaults);
  $('reload-faults').addEventListener('click', loadFaults);
  $('csv').addEventListener('click', exportCsv);
  loadOverview().then(() => document.body.setAttribute('data-ready', 'true'));
});
