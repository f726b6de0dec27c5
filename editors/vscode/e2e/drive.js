#!/usr/bin/env node
// Drives a running code-server (with the bt-lsp extension installed) from headless Chromium and
// prints what a user would see as one JSON object on the last line of stdout.
//
//   node drive.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "tree.xml",
//                   "line": 2, "column": 22, "fixTitle": "Rename 'Main Tree'",
//                   "expectAfter": "Main_Tree", "shotDir": "/tmp/shots"}'
//
// line/column (1-based) point into the name that has the problem. Steps: open the file with
// Quick Open, wait for the error squiggle, read the Problems view, show the hover at line:column,
// open the quick fixes there with Ctrl+., apply the one whose title starts with fixTitle, read
// the buffer until it contains expectAfter, wait for the problem to go away, save with Ctrl+S.
// Screenshots: hover.png, quickfix.png, fixed.png in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed; the JSON
// is printed either way, with `error` and `failedStep` on failure.

'use strict';

const path = require('node:path');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, gotoPosition, openFile, loadWorkbench, run } = driver(
  'drive',
  config,
);

async function problemRows(page) {
  return page.$$eval('.markers-panel .monaco-list-row', (rows) =>
    rows.map((r) => (r.getAttribute('aria-label') || '') + ' | ' + r.innerText.replace(/\s+/g, ' ').trim()),
  );
}

/** The editor's visible text, lines in screen order, non-breaking spaces as spaces. */
async function editorText(page) {
  return page.$eval('.editor-instance .monaco-editor .view-lines', (el) =>
    [...el.querySelectorAll('.view-line')]
      .map((line) => ({ top: parseFloat(line.style.top) || 0, text: line.textContent.replace(/\u00a0/g, ' ') }))
      .sort((a, b) => a.top - b.top)
      .map((line) => line.text)
      .join('\n'),
  );
}

async function main(page) {
  mark('load workbench');
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);
  await page.waitForSelector('.editor-instance .monaco-editor .view-lines', { timeout: STEP_TIMEOUT });
  result.textBefore = await editorText(page);

  mark('wait for squiggle');
  // The first diagnostics come after the server has started: allow for a slow start.
  result.squiggle = await page
    .waitForSelector('.editor-instance .squiggly-error', { timeout: SERVER_TIMEOUT })
    .then(() => true, () => false);
  if (!result.squiggle) {
    throw new Error(`no error squiggle within ${SERVER_TIMEOUT} ms (is the server running? see its log)`);
  }

  mark('problems view');
  await page.keyboard.press('Control+Shift+M');
  await page.waitForSelector('.markers-panel', { state: 'visible', timeout: STEP_TIMEOUT });
  result.problemsBefore = await until(async () => {
    const rows = await problemRows(page);
    return rows.length >= 2 ? rows : null; // the file's row and at least one problem
  }, STEP_TIMEOUT) || (await problemRows(page));

  mark('hover');
  await page.click('.editor-instance .monaco-editor .view-lines');
  await gotoPosition(page, config.line, config.column);
  await page.keyboard.press('Control+K');
  await page.keyboard.press('Control+I');
  const hoverSelector = '.monaco-editor .monaco-hover:not(.hidden) .monaco-hover-content';
  await page.waitForSelector(hoverSelector, { state: 'visible', timeout: STEP_TIMEOUT });
  // The hover fills in as providers answer: wait until its text stops changing.
  let previous = '';
  result.hover = await until(async () => {
    const text = await page.$eval(hoverSelector, (el) => el.innerText).catch(() => '');
    const stable = text !== '' && text === previous;
    previous = text;
    return stable ? text : null;
  }, STEP_TIMEOUT, 500) || previous;
  result.hoverParts = await page.$$eval(`${hoverSelector} .hover-row`, (rows) =>
    rows.map((r) => ({ marker: r.querySelector('.marker') !== null, text: r.innerText })),
  );
  await page.screenshot({ path: path.join(config.shotDir, 'hover.png') });
  await page.keyboard.press('Escape');

  mark('quick fix');
  await page.keyboard.press('Control+.');
  await page.waitForSelector('.action-widget', { state: 'visible', timeout: STEP_TIMEOUT });
  result.actions = await until(async () => {
    const rows = await page.$$eval('.action-widget .monaco-list-row', (rs) => rs.map((r) => r.innerText.trim()));
    return rows.some((r) => r.startsWith(config.fixTitle)) ? rows : null;
  }, STEP_TIMEOUT) || (await page.$$eval('.action-widget .monaco-list-row', (rs) => rs.map((r) => r.innerText.trim())));
  await page.screenshot({ path: path.join(config.shotDir, 'quickfix.png') });
  // Move the keyboard focus to the wanted action (a click would hit the widget's pointer block).
  const chosen = await until(async () => {
    const focused = await page
      .$eval('.action-widget .monaco-list-row.action.focused', (r) => r.getAttribute('aria-label') || r.innerText)
      .catch(() => '');
    if (focused.startsWith(config.fixTitle)) {
      return focused;
    }
    await page.keyboard.press('ArrowDown');
    return null;
  }, 5000, 100);
  if (!chosen) {
    throw new Error(`no code action starting with ${JSON.stringify(config.fixTitle)}`);
  }
  result.appliedAction = chosen;
  await page.keyboard.press('Enter');

  mark('buffer after fix');
  result.textAfter = await until(async () => {
    const text = await editorText(page);
    return text.includes(config.expectAfter) ? text : null;
  }, STEP_TIMEOUT) || (await editorText(page));

  mark('problems after fix');
  result.problemsAfter = await until(async () => {
    const rows = await problemRows(page);
    const squiggles = await page.$$('.editor-instance .squiggly-error');
    return rows.length === 0 && squiggles.length === 0 ? rows : null;
  }, STEP_TIMEOUT) || (await problemRows(page));
  result.squigglesAfter = (await page.$$('.editor-instance .squiggly-error')).length;
  result.problemsViewMessage = await page
    .$eval('.markers-panel .message-box-container, .markers-panel .monaco-tl-contents', (el) => el.innerText.trim())
    .catch(() => '');

  mark('save');
  await page.click('.editor-instance .monaco-editor .view-lines');
  await page.keyboard.press('Control+S');
  result.saved = await page
    .waitForSelector(`.tabs-container .tab.dirty[aria-label*="${config.file}"]`, { state: 'detached', timeout: STEP_TIMEOUT })
    .then(() => true, () => false);
  await page.screenshot({ path: path.join(config.shotDir, 'fixed.png') });
  result.statusBar = await page.$$eval('.statusbar-item', (items) =>
    items.filter((item) => item.innerText.includes('bt-lsp')).map((item) => item.innerText.trim()),
  );
  mark('done');
}

run(main, { viewport: { width: 1280, height: 800 }, failureShot: 'failure.png' });
