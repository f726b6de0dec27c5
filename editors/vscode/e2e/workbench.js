// What the code-server drivers (drive.js, tree.js) share: the run's record and its steps,
// polling, moving the cursor, opening a file with Quick Open, and headless Chromium set up,
// run and torn down so that the JSON record is printed whatever happens.

'use strict';

const path = require('node:path');
const { chromium } = require('playwright-core');

/**
 * A driver run for `config` (the JSON of argv[2]); `tag` prefixes its step lines on stderr.
 * `run(main, options)` launches the browser, calls `main(page)`, prints `result` as the last
 * line of stdout and exits 0, or 1 when a step failed (with `failedStep` and `error`).
 */
function driver(tag, config) {
  const STEP_TIMEOUT = config.stepTimeoutMs || 20000;
  const SERVER_TIMEOUT = config.serverTimeoutMs || 60000;
  const result = { steps: [], consoleErrors: [] };
  const started = Date.now();
  let step = 'start';

  function mark(name) {
    step = name;
    result.steps.push({ step: name, atMs: Date.now() - started });
    process.stderr.write(`[${tag}] ${name}\n`);
  }

  /** Polls fn() until it returns a truthy value; returns it (or the last value after the timeout). */
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

  async function gotoPosition(page, line, column) {
    await page.keyboard.press('Control+G');
    await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
    await page.keyboard.type(`${line}:${column}`);
    await page.keyboard.press('Enter');
    await page.waitForSelector('.quick-input-widget', { state: 'hidden', timeout: STEP_TIMEOUT });
  }

  /** Opens `file` with Quick Open (retried: the file index fills in after the workbench loads). */
  async function openFile(page, file) {
    const opened = await until(async () => {
      await page.keyboard.press('Escape');
      await page.keyboard.press('Control+P');
      const input = await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: 5000 }).catch(() => null);
      if (!input) {
        return false;
      }
      await page.keyboard.type(file);
      const row = await page
        .waitForSelector(`.quick-input-list .monaco-list-row[aria-label*="${file}"]`, { timeout: 5000 })
        .catch(() => null);
      if (!row) {
        return false;
      }
      await page.keyboard.press('Enter');
      return page
        .waitForSelector(`.tabs-container .tab[aria-label*="${file}"]`, { timeout: 5000 })
        .then(() => true, () => false);
    }, STEP_TIMEOUT, 500);
    if (!opened) {
      throw new Error(`could not open ${file} with Quick Open`);
    }
  }

  /** Loads the workbench and waits until the explorer lists `file` (the remote file system answers). */
  async function loadWorkbench(page, file) {
    await page.goto(config.url);
    await page.waitForSelector('.monaco-workbench', { timeout: SERVER_TIMEOUT });
    await page.waitForSelector(`.explorer-folders-view .monaco-list-row[aria-label*="${file}"]`, {
      timeout: SERVER_TIMEOUT,
    });
  }

  /** Runs `main(page)` in headless Chromium; `failureShot` is the screenshot taken when it fails. */
  function run(main, { viewport, failureShot }) {
    (async () => {
      let exitCode = 0;
      const browser = await chromium.launch({
        executablePath: config.chromium || '/usr/bin/chromium',
        headless: true,
        args: [
          '--no-sandbox',
          '--disable-gpu',
          '--disable-dev-shm-usage',
          '--disable-background-networking',
          '--disable-component-update',
          '--disable-sync',
          '--no-first-run',
        ],
      });
      const page = await browser.newPage({ viewport });
      page.on('console', (message) => {
        if (message.type() === 'error') {
          result.consoleErrors.push(message.text().slice(0, 300));
        }
      });
      try {
        await main(page);
      } catch (error) {
        exitCode = 1;
        result.failedStep = step;
        result.error = String(error && error.stack ? error.stack : error);
        await page.screenshot({ path: path.join(config.shotDir, failureShot) }).catch(() => {});
      } finally {
        result.elapsedMs = Date.now() - started;
        await browser.close().catch(() => {});
      }
      process.stdout.write(JSON.stringify(result) + '\n');
      process.exit(exitCode);
    })();
  }

  return { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, gotoPosition, openFile, loadWorkbench, run };
}

module.exports = { driver };
