#!/usr/bin/env node
// Drives "bt-lsp: Connect to a Running Tree" in a running code-server (with the bt-lsp extension
// installed) against a real BehaviorTree.CPP executor, from headless Chromium, and prints what a
// user would see as one JSON object on the last line of stdout.
//
//   node live.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "mission.xml", "otherFile": "b.xml",
//                  "address": "127.0.0.1:41000", "badAddress": "127.0.0.1:99999",
//                  "executorPid": 1234, "restart": ["/usr/bin/python3", "executor.py", ...],
//                  "shotDir": "/tmp/shots"}'
//
// Steps: open the file, run "bt-lsp: Show Tree" and wait for its picture (the server runs); run
// "bt-lsp: Connect to a Running Tree", type badAddress (read the input box's validation message),
// then address; wait until the picture's nodes have live-* classes, the editor shows the statuses'
// after-texts and the status bar says connected; screenshot; type a space at the end of line 1
// and read the classes of the picture drawn again; open otherFile (its picture has no statuses),
// then the file again (its editor and picture get their statuses back); kill the executor (executorPid) and
// wait for the status bar to say lost (reading the classes and after-texts left); start the
// executor again with `restart` (its "ready" line) and wait for connected and statuses again; run
// "bt-lsp: Disconnect from the Running Tree" and wait for off.
// Screenshots: live.png (connected), live-lost.png, live-failure.png on failure, in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const path = require('node:path');
const { spawn } = require('node:child_process');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, gotoPosition, openFile, loadWorkbench, run } = driver(
  'live',
  config,
);

/** The frame of the tree webview (nested iframes in the workbench), once its script has run. */
async function treeFrame(page) {
  for (const frame of page.frames()) {
    const found = await frame.$('#canvas').catch(() => null);
    if (found) {
      return frame;
    }
  }
  return null;
}

/** The picture's nodes: type, name (from the title) and live class; the count the page keeps. */
async function picture(frame) {
  return frame.evaluate(() => {
    const nodes = [...document.querySelectorAll('#canvas g.node')].map((g) => ({
      id: g.id,
      type: g.dataset.type,
      title: (g.querySelector('title') || {}).textContent || '',
      live: [...g.classList].filter((c) => c.startsWith('live-')),
      fill: getComputedStyle(g.querySelector('.shape')).fill,
    }));
    return {
      nodes,
      live: parseInt(document.body.dataset.live || '0', 10),
      renders: parseInt(document.body.dataset.renders || '0', 10),
    };
  });
}

/** The statuses written after the nodes' tag names in the editor (decorations' after-texts). */
async function afterTexts(page) {
  return page.$$eval('.editor-instance .view-lines span', (spans) =>
    spans
      .map((s) => getComputedStyle(s, '::after').content)
      .filter((c) => c && c.includes('●'))
      .map((c) => c.replace(/^"|"$/g, '').trim()),
  );
}

async function liveItem(page) {
  return page
    .$$eval('.statusbar-item', (items) =>
      items.filter((i) => i.innerText.includes('BT live:')).map((i) => i.innerText.trim()),
    )
    .then((texts) => texts[0] || null);
}

/** Everything at once, for the record. */
async function snapshot(page, frame) {
  const p = await picture(frame);
  return {
    status: await liveItem(page),
    after: await afterTexts(page),
    live: p.live,
    renders: p.renders,
    classes: Object.fromEntries(p.nodes.filter((n) => n.live.length).map((n) => [n.id, n.live.join(' ')])),
    nodes: p.nodes,
  };
}

async function command(page, title) {
  await page.click('.editor-instance .monaco-editor .view-lines');
  await page.keyboard.press('F1');
  await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
  await page.keyboard.type(title);
  await page.waitForSelector(`.quick-input-list .monaco-list-row[aria-label*="${title.replace('bt-lsp: ', '')}"]`, {
    timeout: STEP_TIMEOUT,
  });
  await page.keyboard.press('Enter');
}

/** Starts the executor again; resolves with the process once it printed "ready". */
function restartExecutor() {
  return new Promise((resolve, reject) => {
    const [program, ...args] = config.restart;
    const child = spawn(program, args, { stdio: ['ignore', 'pipe', 'inherit'] });
    let out = '';
    const timer = setTimeout(() => reject(new Error('the restarted executor printed no "ready"')), 15000);
    child.stdout.on('data', (chunk) => {
      out += chunk.toString();
      if (/^ready$/m.test(out)) {
        clearTimeout(timer);
        child.stdout.removeAllListeners('data');
        child.stdout.resume(); // its result lines go nowhere
        resolve(child);
      }
    });
    child.on('error', reject);
  });
}

/** Live classes on some nodes, with the statuses' after-texts in the editor and `state` in the status bar. */
async function waitLive(page, frame, state) {
  return until(async () => {
    const s = await snapshot(page, frame);
    return s.live > 0 && s.after.length > 0 && (s.status || '').includes(`BT live: ${state}`) ? s : null;
  }, SERVER_TIMEOUT, 200);
}

let restarted = null;

async function main(page) {
  mark('load workbench');
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);
  await page.keyboard.press('Control+B'); // the side bar away: room for the editor and the tree

  mark('show tree');
  await command(page, 'bt-lsp: Show Tree');
  const frame = await until(() => treeFrame(page), STEP_TIMEOUT, 300);
  if (!frame) {
    throw new Error('no tree webview appeared');
  }
  const drawn = await until(async () => {
    const p = await picture(frame);
    return p.nodes.length > 0 ? p : null;
  }, SERVER_TIMEOUT);
  if (!drawn) {
    throw new Error('the webview shows no tree (is the server running?)');
  }
  result.before = await snapshot(page, frame);

  mark('connect');
  await command(page, 'bt-lsp: Connect to a Running Tree');
  await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
  result.defaultAddress = await page.$eval('.quick-input-widget input', (i) => i.value);
  await page.keyboard.press('Control+A');
  await page.keyboard.type(config.badAddress);
  const message = () =>
    page.$eval('.quick-input-widget .quick-input-message', (m) => m.innerText.trim()).catch(() => '');
  result.validation = await until(async () => {
    const text = await message();
    return text.includes(config.badAddressMessage) ? text : null;
  }, STEP_TIMEOUT, 100) || (await message());
  await page.keyboard.press('Enter'); // refused: the box stays
  result.stillAsking = await page.isVisible('.quick-input-widget input');
  await page.keyboard.press('Control+A');
  await page.keyboard.type(config.address);
  await page.keyboard.press('Enter');

  mark('connected');
  result.connected = await waitLive(page, frame, 'connected');
  if (!result.connected) {
    result.connected = await snapshot(page, frame);
    throw new Error('no live statuses within the timeout');
  }
  // A moment later: a mix of statuses for the picture.
  result.mix = await until(async () => {
    const s = await snapshot(page, frame);
    const kinds = new Set(Object.values(s.classes));
    return kinds.has('live-running') && kinds.has('live-failure') && kinds.size >= 3 && s.after.length > 0 ? s : null;
  }, STEP_TIMEOUT, 50) || (await snapshot(page, frame));
  await page.screenshot({ path: path.join(config.shotDir, 'live.png') });

  mark('edit: the picture is drawn again');
  const renders = result.mix.renders;
  await page.click('.editor-instance .monaco-editor .view-lines');
  await gotoPosition(page, 1, 999); // the end of <root ...>: no node moves
  await page.keyboard.type(' ');
  result.redrawn = await until(async () => {
    const s = await snapshot(page, frame);
    return s.renders > renders ? s : null;
  }, STEP_TIMEOUT, 100) || (await snapshot(page, frame));

  mark('another file, then back');
  await openFile(page, config.otherFile);
  result.other = await until(async () => {
    const s = await snapshot(page, frame);
    return s.nodes.length !== result.mix.nodes.length ? s : null;
  }, STEP_TIMEOUT, 100) || (await snapshot(page, frame));
  await page.click(`.tabs-container .tab[aria-label*="${config.file}"]`); // its tab, still open
  result.back = await waitLive(page, frame, 'connected') || (await snapshot(page, frame));

  mark('executor killed');
  process.kill(config.executorPid, 'SIGKILL');
  result.lost = await until(async () => {
    const s = await snapshot(page, frame);
    return (s.status || '').includes('BT live: lost') ? s : null;
  }, SERVER_TIMEOUT, 200) || (await snapshot(page, frame));
  await page.screenshot({ path: path.join(config.shotDir, 'live-lost.png') });

  mark('executor restarted');
  restarted = await restartExecutor();
  result.reconnected = await waitLive(page, frame, 'connected') || (await snapshot(page, frame));

  mark('disconnect');
  await command(page, 'bt-lsp: Disconnect from the Running Tree');
  result.off = await until(async () => {
    const s = await snapshot(page, frame);
    return (s.status || '').includes('BT live: off') && s.live === 0 && s.after.length === 0 ? s : null;
  }, STEP_TIMEOUT, 200) || (await snapshot(page, frame));
  mark('done');
}

process.on('exit', () => {
  if (restarted && restarted.exitCode === null) {
    restarted.kill('SIGKILL');
  }
});

run(main, { viewport: { width: 1400, height: 800 }, failureShot: 'live-failure.png' });
