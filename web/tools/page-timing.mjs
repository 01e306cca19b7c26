// Time to interactive of a report page (index.html) in headless Chromium:
// `node --experimental-websocket web/tools/page-timing.mjs PAGE [RUNS]`.
// Each run starts a fresh browser (as scripts/page-screenshots does),
// opens the page from file:// through the DevTools protocol and waits for
// the page's read-out; it prints, per step, the median over the runs of
// the milliseconds since navigation started (the page's own `timings`,
// in real time: no virtual time budget), and the wall time from asking
// for the page to the read-out. A measurement script, not a test.
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';

const [page, runsArg] = process.argv.slice(2);
if (!page) {
  console.error('usage: page-timing.mjs PAGE [RUNS]');
  process.exit(2);
}
const runs = Number(runsArg ?? 5);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function browser() {
  const profile = mkdtempSync(join(tmpdir(), 'page-timing-'));
  const proc = spawn('chromium', [
    '--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader',
    '--enable-unsafe-swiftshader', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--window-size=1280,800',
    `--user-data-dir=${profile}`, '--remote-debugging-port=0', 'about:blank',
  ], { stdio: ['ignore', 'ignore', 'pipe'] });
  const ws = await new Promise((ok) => {
    let err = '';
    proc.stderr.on('data', (d) => {
      err += d;
      const m = /DevTools listening on (ws:\S+)/.exec(err);
      if (m) ok(m[1]);
    });
  });
  const close = async () => {
    const exited = new Promise((ok) => proc.on('exit', ok));
    proc.kill();
    await exited;
    // Chromium's helpers may still write into the profile for a moment.
    for (let k = 0; k < 20; k++) {
      try {
        rmSync(profile, { recursive: true, force: true });
        return;
      } catch {
        await sleep(100);
      }
    }
  };
  return { ws, close };
}

async function target(wsUrl) {
  const http = wsUrl.replace('ws://', 'http://').replace(/\/devtools\/browser\/.*/, '');
  const list = await (await fetch(`${http}/json/list`)).json();
  return list.find((t) => t.type === 'page').webSocketDebuggerUrl;
}

function session(url) {
  const ws = new WebSocket(url);
  let id = 0;
  const waiting = new Map();
  ws.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.id && waiting.has(m.id)) {
      waiting.get(m.id)(m);
      waiting.delete(m.id);
    }
  };
  const send = (method, params = {}) => new Promise((ok) => {
    id += 1;
    waiting.set(id, ok);
    ws.send(JSON.stringify({ id, method, params }));
  });
  return new Promise((ok) => { ws.onopen = () => ok({ send, close: () => ws.close() }); });
}

async function once(file) {
  const b = await browser();
  try {
    const s = await session(await target(b.ws));
    const t0 = performance.now();
    await s.send('Page.navigate', { url: `file://${file}` });
    const expr = "(() => { const r = document.getElementById('readout'); return r && r.textContent; })()";
    for (;;) {
      const r = await s.send('Runtime.evaluate', { expression: expr, returnByValue: true });
      const text = r.result?.result?.value;
      if (text) {
        const wall = performance.now() - t0;
        s.close();
        return { wall, ...JSON.parse(text).timings, ready: JSON.parse(text).readyMs };
      }
      if (performance.now() - t0 > 60000) throw new Error('no read-out within 60 s');
      await sleep(20);
    }
  } finally {
    await b.close();
  }
}

const file = resolve(page);
const rows = [];
for (let k = 0; k < runs; k++) rows.push(await once(file));
const median = (v) => {
  const s = [...v].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};
for (const key of Object.keys(rows[0])) {
  const v = rows.map((r) => r[key]).filter((x) => typeof x === 'number');
  if (v.length) console.log(`${key.padEnd(9)} median ${median(v).toFixed(0).padStart(6)} ms  (${v.map((x) => x.toFixed(0)).join(', ')})`);
}
