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

async function api(path, body) {
  const options = body === undefined ? {} : { method: 'POST', body, headers: { 'Content-Type': 'text/plain' } };
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
    ['Temperature', r.temperature_c === null ? 'unknown' : r.temperature_c.toFixed(1) + ' °C'],
    ['Target', data.target],
  ];
  for (const [k, v] of rows) {
    const tr = el('tr');
    tr.append(el('th', {}, k), el('td', { 'data-key': k }, v));
    table.append(tr);
  }
  $('overview-faults').textContent = data.fault.title + '. ' + data.status.title;
  $('overview-pending').textContent = data.pending.length ? data.pending.join(', ') + ' (a reset makes them live)' : 'none';
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
    if (p.writable && p.fact) edit.append(el('input', { name: p.name, placeholder: p.unit || 'value' }));
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
  const cells = data.cells && data.cells.length ? data.cells : null;
  const steps = data.plan ? data.plan.steps : [];
  if (cells || steps.length) {
    const t = el('table', { class: 'grid' });
    if (cells) {
      t.append(el('tr', {}, ''));
      t.lastChild.append(el('th', {}, 'Cell'), el('th', {}, 'Now on the card'), el('th', {}, 'Outcome'));
      for (const c of cells) {
        const tr = el('tr', { 'data-cell': c.cell });
        tr.append(el('td', {}, c.cell), el('td', {}, c.actual_text), el('td', {}, c.status + (c.error ? ': ' + c.error : '')));
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

let previewed = '';
async function preview() {
  previewed = assignments();
  const { status, data } = await api('/api/preview', previewed);
  const fine = showRun($('change-result'), status, data) && data.plan && data.plan.steps.length > 0;
  $('apply').disabled = !fine;
}

async function apply() {
  $('apply').disabled = true;
  const { status, data } = await api('/api/apply', previewed);
  showRun($('change-result'), status, data);
  await loadParams();
}

// ------------------------------------------------------------------ faults
function bitBox(bit) {
  const box = el('div', { class: 'bit ' + bit.severity });
  box.append(el('h3', {}, (bit.name || 'reserved') + ' (bit ' + bit.bit + ', ' + bit.severity + ')'));
  box.append(el('p', {}, bit.meaning));
  if (bit.cause_now) box.append(el('p', {}, 'now: ' + (bit.cause_now.text || JSON.stringify(bit.cause_now))));
  for (const [title, list] of [['Causes', bit.causes], ['Check', bit.checks]]) {
    if (!list || !list.length) continue;
    box.append(el('p', {}, title + ':'));
    const ul = el('ul');
    for (const item of list) ul.append(el('li', {}, item));
    box.append(ul);
  }
  return box;
}

function showReport(titleEl, bitsEl, report) {
  titleEl.textContent = report.title;
  bitsEl.textContent = '';
  for (const b of report.bits) bitsEl.append(bitBox(b));
  for (const n of report.notes || []) bitsEl.append(el('p', { class: 'hint' }, n));
}

async function loadFaults() {
  const { status, data } = await api('/api/faults');
  if (status !== 200) {
    $('fault-title').textContent = failureText(data);
    return;
  }
  showReport($('fault-title'), $('fault-bits'), data.fault);
  showReport($('status-title'), $('status-bits'), data.status);
}

async function clearFaults() {
  const { status, data } = await api('/api/clear-faults', '');
  const ok = status === 200 && data.outcome === 'done';
  $('clear-result').textContent = '';
  $('clear-result').append(el('div', { class: 'result ' + (ok ? 'ok' : 'refused') },
    data.fault ? 'FAULT ' + data.fault_before + ' before; now ' + data.fault.title : failureText(data)));
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
  $('live-temp').textContent = s.temperature === null ? 'unknown' : s.temperature.toFixed(1) + ' °C';
  $('live-fault').textContent = s.fault + (s.fault_bits.length ? ' ' + s.fault_bits.join(', ') : '');
  $('live-status').textContent = s.status + (s.status_bits.length ? ' ' + s.status_bits.join(', ') : '');
}

function svg(tag, attrs) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  return e;
}

// One series scaled into the plot area: its polyline and its axis labels.
function series(plot, points, key, color, side, unit) {
  const values = points.filter((p) => p[key] !== null && p[key] !== undefined);
  if (!values.length) return;
  let lo = Math.min(...values.map((p) => p[key]));
  let hi = Math.max(...values.map((p) => p[key]));
  if (hi - lo < 1) { lo -= 0.5; hi += 0.5; }
  const now = points[points.length - 1].t;
  const x = (t) => 50 + (700 * (WINDOW_S * 1000 - (now - t))) / (WINDOW_S * 1000);
  const y = (v) => 270 - (250 * (v - lo)) / (hi - lo);
  const line = values.map((p) => x(p.t).toFixed(1) + ',' + y(p[key]).toFixed(1)).join(' ');
  plot.append(svg('polyline', { points: line, fill: 'none', stroke: color, 'stroke-width': 1.5, class: 'series-' + key }));
  const tx = side === 'left' ? 5 : 755;
  for (const v of [lo, hi]) {
    const label = svg('text', { x: tx, y: y(v) + 4, fill: color, 'font-size': 11 });
    label.textContent = v.toFixed(1) + unit;
    plot.append(label);
  }
}

function drawPlot() {
  const plot = $('plot');
  const now = samples.length ? samples[samples.length - 1].t : 0;
  const points = samples.filter((s) => !s.error && now - s.t <= WINDOW_S * 1000);
  plot.textContent = '';
  plot.append(svg('rect', { x: 50, y: 20, width: 700, height: 250, fill: 'none', stroke: '#ccc' }));
  // A red band wherever FAULT was non-zero.
  for (const p of points) {
    if (p.fault === '0x0000') continue;
    const x = 50 + (700 * (WINDOW_S * 1000 - (now - p.t))) / (WINDOW_S * 1000);
    plot.append(svg('rect', { x: x - 1, y: 20, width: 2, height: 250, fill: '#fcc' }));
  }
  series(plot, points, 'busv', '#1565c0', 'left', ' V');
  series(plot, points, 'temperature', '#c62828', 'right', ' °C');
  const caption = svg('text', { x: 50, y: 290, 'font-size': 11, fill: '#555' });
  caption.textContent = 'last ' + WINDOW_S + ' s: bus voltage (blue, left), temperature (red, right), FAULT set (red band)';
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
