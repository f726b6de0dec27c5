#!/usr/bin/env node
// Drives a code-server whose btLsp.server.command names a program that is not installed yet
// through a failed start and its recovery, from headless Chromium; prints what a user would
// see as one JSON object on the last line of stdout.
//
//   node restart.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "tree.xml",
//                     "installPath": "/tmp/bin/bt-lsp", "installScript": "#!/bin/sh\n...",
//                     "shotDir": "/tmp/shots"}'
//
// Steps: open the file (which starts the extension), wait for bt-lsp's error notification and
// read its text and buttons; install the server where the setting says (write installScript
// to installPath); press the notification's "Restart server"; wait for the error squiggle of
// the file (the server runs); then read every notification (the toasts and the notification
// center).
// Screenshots: failed.png, recovered.png in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const fs = require('node:fs');
const path = require('node:path');
const { chromium } = require('playwright-core');

const config = JSON.parse(process.argv[2] || '{}');
const STEP_TIMEOUT = config.stepTimeoutMs || 20000;
const SERVER_TIMEOUT = config.serverTimeoutMs || 60000;
const CHROMIUM = config.chromium || '/usr/bin/chromium';

const result = { steps: [] };
let step = 'start';
const started = Date.now();

function mark(name) {
  step = name;
  result.steps.push({ step: name, atMs: Date.now() - started });
  process.stderr.write(`[restart] ${name}\n`);
}

async function until(fn, timeoutMs, intervalMs = 250) {
  const deadline = Date.now() + timeoutMs;
  let value;
  for (;;) {
    value = await fn();
    if (value || Date.now() > deadline) {
      return value;
    }
    await new Promise((resolve) => setTimeout(resolve, intervalMs));
  }
}

/** The bt-lsp notifications shown as toasts: their message and their buttons. */
async function toasts(page) {
  return page.$$eval('.notifications-toasts .notification-list-item', (items) =>
    items
      .map((item) => ({
        message: (item.querySelector('.notification-list-item-message') || item).innerText.trim(),
        buttons: [...item.querySelectorAll('.monaco-button')].map((b) => b.innerText.trim()).filter(Boolean),
      }))
      .filter((n) => n.message.includes('bt-lsp') || /notification|stack|Error/.test(n.message)),
  );
}

async function main(page) {
  mark('load workbench');
  await page.goto(config.url);
  await page.waitForSelector('.monaco-workbench', { timeout: SERVER_TIMEOUT });
  await page.waitForSelector(`.explorer-folders-view .monaco-list-row[aria-label*="${config.file}"]`, {
    timeout: SERVER_TIMEOUT,
  });

  mark('open file');
  const opened = await until(async () => {
    await page.keyboard.press('Escape');
    await page.keyboard.press('Control+P');
    const input = await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: 5000 }).catch(() => null);
    if (!input) {
      return false;
    }
    await page.keyboard.type(config.file);
    const row = await page
      .waitForSelector(`.quick-input-list .monaco-list-row[aria-label*="${config.file}"]`, { timeout: 5000 })
      .catch(() => null);
    if (!row) {
      return false;
    }
    await page.keyboard.press('Enter');
    return page
      .waitForSelector(`.tabs-container .tab[aria-label*="${config.file}"]`, { timeout: 5000 })
      .then(() => true, () => false);
  }, STEP_TIMEOUT, 500);
  if (!opened) {
    throw new Error(`could not open ${config.file} with Quick Open`);
  }

  mark('failed start notification');
  result.failed = await until(async () => {
    const found = await toasts(page);
    return found.some((n) => n.message.startsWith('bt-lsp:')) ? found : null;
  }, SERVER_TIMEOUT, 500) || (await toasts(page));
  await page.screenshot({ path: path.join(config.shotDir, 'failed.png') });
  if (!result.failed.some((n) => n.buttons.includes('Restart server'))) {
    throw new Error('no bt-lsp notification with a "Restart server" button');
  }
  // Nothing may have started: no squiggle before the command is fixed.
  result.squiggleBeforeFix = (await page.$$('.editor-instance .squiggly-error')).length;

  mark('install the server');
  // What the notification asks for: the command of the setting now exists.
  fs.mkdirSync(path.dirname(config.installPath), { recursive: true });
  fs.writeFileSync(config.installPath, config.installScript, { mode: 0o755 });
  result.installed = fs.existsSync(config.installPath);

  mark('press Restart server');
  const button = page
    .locator('.notifications-toasts .notification-list-item')
    .filter({ hasText: 'bt-lsp:' })
    .locator('.monaco-button', { hasText: 'Restart server' })
    .first();
  result.pressedRestart = await button.click({ timeout: 5000 }).then(() => true, () => false);

  mark('wait for diagnostics');
  result.squiggle = await page
    .waitForSelector('.editor-instance .squiggly-error', { timeout: SERVER_TIMEOUT })
    .then(() => true, () => false);
  // Let any late notification of the failed start or of the restart arrive.
  await new Promise((resolve) => setTimeout(resolve, 4000));
  result.toastsAfter = await toasts(page);
  await page.screenshot({ path: path.join(config.shotDir, 'recovered.png') });

  mark('notification center');
  await page.keyboard.press('F1');
  await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
  await page.keyboard.type('Notifications: Show Notifications');
  await page.waitForSelector('.quick-input-list .monaco-list-row', { timeout: STEP_TIMEOUT });
  await page.keyboard.press('Enter');
  await page.waitForSelector('.notifications-center', { state: 'visible', timeout: STEP_TIMEOUT }).catch(() => null);
  result.centerAfter = await page.$$eval('.notifications-center .notification-list-item-message', (items) =>
    items.map((m) => m.innerText.trim()),
  );
  mark('done');
}

(async () => {
  let exitCode = 0;
  const browser = await chromium.launch({
    executablePath: CHROMIUM,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--disable-background-networking', '--no-first-run'],
  });
  const context = await browser.newContext({ viewport: { width: 1280, height: 800 } });
  await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: new URL(config.url).origin });
  const page = await context.newPage();
  try {
    await main(page);
  } catch (error) {
    exitCode = 1;
    result.failedStep = step;
    result.error = String(error && error.stack ? error.stack : error);
    await page.screenshot({ path: path.join(config.shotDir, 'failure.png') }).catch(() => {});
  } finally {
    result.elapsedMs = Date.now() - started;
    await browser.close().catch(() => {});
  }
  process.stdout.write(JSON.stringify(result) + '\n');
  process.exit(exitCode);
})();
