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
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, openFile, loadWorkbench, run } = driver(
  'restart',
  config,
);

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
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);

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

run(main, { viewport: { width: 1280, height: 800 }, failureShot: 'failure.png' });
