#!/usr/bin/env node
// Drives "bt-lsp: Replay a .btlog" in a running code-server (with the bt-lsp extension
// installed) from headless Chromium and prints what a user would see as one JSON object on the
// last line of stdout.
//
//   node replay.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "mission.xml",
//                    "log": "run.btlog", "seeks": [1, 9, 40], "shotDir": "/tmp/shots"}'
//
// Steps: open the file, run "bt-lsp: Show Tree" and wait for its picture; run "bt-lsp: Replay a
// .btlog" and pick `log`; in the timeline (the panel area), move the slider to each of `seeks`
// (transitions applied) and read the picture's live classes, the editor's after-texts and the
// status bar; press ⇤ then ▶ and wait for the end; press ■ and read what is left (the timeline
// view hidden).
// Screenshots: replay.png (at the second seek), replay-failure.png on failure, in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const path = require('node:path');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, openFile, loadWorkbench, run } = driver('replay', config);

async function frameWith(page, selector) {
  for (const frame of page.frames()) {
    const found = await frame.$(selector).catch(() => null);
    if (found) {
      return frame;
    }
  }
  return null;
}

/** The picture's nodes in order: type and live class. */
async function picture(frame) {
  return frame.evaluate(() => ({
    nodes: [...document.querySelectorAll('#canvas g.node')].map((g) => ({
      type: g.dataset.type,
      live: [...g.classList].filter((c) => c.startsWith('live-')).join(' '),
    })),
    live: parseInt(document.body.dataset.live || '0', 10),
  }));
}

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
    .$$eval('.statusbar-item', (items) => items.filter((i) => i.innerText.includes('BT live:')).map((i) => i.innerText.trim()))
    .then((texts) => texts[0] || null);
}

async function timelineState(frame) {
  return frame.evaluate(() => ({
    applied: parseInt(document.body.dataset.applied || '-1', 10),
    playing: document.body.dataset.playing === 'true',
    ended: document.body.dataset.ended === 'true',
    max: parseInt(document.getElementById('timeline').max, 10),
    where: document.getElementById('where').textContent,
    last: document.getElementById('last').textContent,
  }));
}

async function snapshot(page, tree, timeline) {
  return {
    timeline: await timelineState(timeline),
    picture: await picture(tree),
    after: await afterTexts(page),
    status: await liveItem(page),
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

async function main(page) {
  mark('load workbench');
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);
  await page.keyboard.press('Control+B');

  mark('show tree');
  await command(page, 'bt-lsp: Show Tree');
  const tree = await until(() => frameWith(page, '#canvas'), STEP_TIMEOUT, 300);
  if (!tree || !(await until(async () => (await picture(tree)).nodes.length > 0, SERVER_TIMEOUT))) {
    throw new Error('no tree picture (is the server running?)');
  }

  mark('replay');
  await command(page, 'bt-lsp: Replay a .btlog');
  await page.waitForSelector(`.quick-input-list .monaco-list-row[aria-label*="${config.log}"]`, { timeout: STEP_TIMEOUT });
  await page.keyboard.type(config.log);
  await page.keyboard.press('Enter');
  const timeline = await until(() => frameWith(page, '#timeline'), STEP_TIMEOUT, 300);
  if (!timeline) {
    throw new Error('no replay timeline appeared');
  }
  result.opened = await until(async () => {
    const s = await snapshot(page, tree, timeline);
    return s.timeline.applied === 0 && s.picture.live > 0 ? s : null;
  }, STEP_TIMEOUT, 200) || (await snapshot(page, tree, timeline));

  result.seeks = [];
  for (const [i, k] of config.seeks.entries()) {
    mark(`seek ${k}`);
    await timeline.$eval('#timeline', (el, value) => {
      el.value = String(value);
      el.dispatchEvent(new Event('input', { bubbles: true }));
    }, k);
    const s = await until(async () => {
      const now = await snapshot(page, tree, timeline);
      return now.timeline.applied === k ? now : null;
    }, STEP_TIMEOUT, 100) || (await snapshot(page, tree, timeline));
    // The editor and the picture follow the same message: give them a moment to agree.
    await new Promise((resolve) => setTimeout(resolve, 400));
    const settled = await snapshot(page, tree, timeline);
    result.seeks.push({ k, ...settled, first: s.timeline.applied });
    if (i === 1) {
      await page.screenshot({ path: path.join(config.shotDir, 'replay.png') });
    }
  }

  mark('play');
  await timeline.click('#start');
  await until(async () => (await timelineState(timeline)).applied === 0, STEP_TIMEOUT, 100);
  await timeline.click('#play');
  const seen = new Set();
  result.played = await until(async () => {
    const t = await timelineState(timeline);
    seen.add(t.applied);
    return t.applied === t.max && !t.playing ? t : null;
  }, SERVER_TIMEOUT, 20) || (await timelineState(timeline));
  result.playedThrough = [...seen].sort((a, b) => a - b);

  mark('stop');
  await timeline.click('#stop');
  // The timeline view hides (its frame goes) and the statuses go.
  const stopped = async () => ({
    timelineShown: !timeline.isDetached() && (await frameWith(page, '#timeline')) !== null,
    picture: await picture(tree),
    after: await afterTexts(page),
    status: await liveItem(page),
  });
  result.stopped = await until(async () => {
    const s = await stopped();
    return !s.timelineShown && s.picture.live === 0 && s.after.length === 0 ? s : null;
  }, STEP_TIMEOUT, 200) || (await stopped());
  mark('done');
}

run(main, { viewport: { width: 1400, height: 900 }, failureShot: 'replay-failure.png' });
