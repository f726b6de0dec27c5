#!/usr/bin/env node
// Drives a code-server where the bt-lsp server cannot start and prints what a user sees, as
// one JSON object on the last line of stdout: the status bar item, the Problems view, the
// notification.
//
//   node notrunning.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "tree.xml",
//                        "shotDir": "/tmp/shots"}'
//
// Steps: open the file (which starts the extension), wait for the warning squiggle that says
// the file was not checked, read the bt-lsp status bar item (text and background colour), the
// Problems view and the bt-lsp notification. Screenshot: notrunning.png in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const path = require('node:path');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, openFile, loadWorkbench, run } = driver(
  'notrunning',
  config,
);

/** The status bar items whose text names bt-lsp, with their computed background colour. */
async function statusItems(page) {
  return page.$$eval('.statusbar-item', (items) =>
    items
      .filter((item) => item.innerText.includes('bt-lsp'))
      .map((item) => ({ text: item.innerText.trim(), background: getComputedStyle(item).backgroundColor })),
  );
}

async function main(page) {
  mark('load workbench');
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);

  mark('wait for the not-checked warning');
  result.squiggle = await page
    .waitForSelector('.editor-instance .squiggly-warning', { timeout: SERVER_TIMEOUT })
    .then(() => true, () => false);

  mark('status bar');
  result.statusBar = await until(async () => {
    const items = await statusItems(page);
    return items.some((i) => i.text.includes('not running')) ? items : null;
  }, STEP_TIMEOUT) || (await statusItems(page));

  mark('problems view');
  await page.keyboard.press('Control+Shift+M');
  await page.waitForSelector('.markers-panel', { state: 'visible', timeout: STEP_TIMEOUT });
  const rows = () =>
    page.$$eval('.markers-panel .monaco-list-row', (rs) =>
      rs.map((r) => (r.getAttribute('aria-label') || '') + ' | ' + r.innerText.replace(/\s+/g, ' ').trim()),
    );
  result.problems = await until(async () => {
    const found = await rows();
    return found.length >= 2 ? found : null;
  }, STEP_TIMEOUT) || (await rows());

  mark('notification');
  result.notifications = await page.$$eval('.notifications-toasts .notification-list-item', (items) =>
    items.map((item) => (item.querySelector('.notification-list-item-message') || item).innerText.trim()),
  );
  await page.screenshot({ path: path.join(config.shotDir, 'notrunning.png') });
  mark('done');
}

run(main, { viewport: { width: 1280, height: 800 }, failureShot: 'failure.png' });
