#!/usr/bin/env node
// Drives the `bt` debugger (Run and Debug with a launch.json attach configuration) in a running
// code-server with the bt-lsp extension installed, against real BehaviorTree.CPP executors it
// starts itself (so that it reads their `result ...` lines as they come), from headless Chromium,
// and prints what a user would see as one JSON object on the last line of stdout.
//
//   node debug.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "mission.xml", "line": 13,
//                   "mainTree": "Mission", "mainFrame": "Sequence \"mission\"",
//                   "executor": ["/usr/bin/python3", "executor.py", "41000", "300", "/ws/mission.xml"],
//                   "shotDir": "/tmp/shots"}'
//
// Steps: start the executor and open the file; F9 on `line` (a breakpoint in the gutter); F5 (the
// launch.json configuration) and wait until VS Code stops there (the debug toolbar's Continue, the
// stack frame's glyph and line highlight on `line`, the whole Call Stack); read the Variables view
// (its scopes, then "All blackboards" and the `mainTree` blackboard expanded for `counter`);
// screenshot; select the `mainFrame` frame (its line highlighted, its tree's blackboard shown);
// run "bt-lsp: Fail node" and wait for the executor's next result, then the next stop;
// Continue (the toolbar) and the same; Shift+F5 and wait for three more results (no hook left).
// Then, with that executor stopped: F5 again (the breakpoint is pending: its glyph, the Breakpoints
// view's message, the Debug Console), start the executor again on the same port and wait for the
// breakpoint to be verified and the tree to stop there; Shift+F5 and three more results.
// What each executor printed (`executors`: counts of each line) and each step's time are in the record.
// Screenshots: debug.png (stopped), debug-pending.png, debug-failure.png on failure, in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const path = require('node:path');
const { spawn } = require('node:child_process');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, gotoPosition, openFile, loadWorkbench, run } = driver(
  'debug',
  config,
);
const started = Date.now();
const children = [];
result.executors = [];

/** Starts an executor; once it printed "ready", resolves with its lines ({lines: [{atMs, line}]}) and
 * its process. What it printed is summed up in result.executors (the record is printed whole and
 * must stay small: a result a tick). */
function startExecutor() {
  return new Promise((resolve, reject) => {
    const [program, ...args] = config.executor;
    const child = spawn(program, args, { stdio: ['ignore', 'pipe', 'inherit'] });
    children.push(child);
    const record = { lines: [] };
    const summary = { pid: child.pid, printed: {}, exit: null };
    result.executors.push(summary);
    let rest = '';
    const timer = setTimeout(() => reject(new Error('the executor printed no "ready"')), STEP_TIMEOUT);
    child.stdout.on('data', (chunk) => {
      const parts = (rest + chunk.toString()).split('\n');
      rest = parts.pop();
      for (const line of parts) {
        record.lines.push({ atMs: Date.now() - started, line: line.trim() });
        summary.printed[line.trim()] = (summary.printed[line.trim()] || 0) + 1;
        if (line.trim() === 'ready') {
          clearTimeout(timer);
          resolve({ record, child });
        }
      }
    });
    child.on('exit', (code, signal) => {
      summary.exit = { code, signal, atMs: Date.now() - started };
    });
    child.on('error', reject);
  });
}

/** The `result ...` lines of an executor from line index `from` on. */
function resultsFrom(executor, from) {
  return executor.lines.slice(from).filter((l) => l.line.startsWith('result '));
}

async function waitResults(executor, from, count, what) {
  const found = await until(() => {
    const results = resultsFrom(executor, from);
    return results.length >= count ? results : null;
  }, SERVER_TIMEOUT, 100);
  if (!found) {
    throw new Error(`the executor printed no ${what}: ${JSON.stringify(executor.lines.slice(from))}`);
  }
  return found;
}

/** The glyphs of the editor's gutter and the lines of the top stack frame's highlight, by line number. */
async function gutter(page) {
  return page.evaluate(() => {
    const editor = document.querySelector('.editor-instance .monaco-editor');
    if (!editor) {
      return { glyphs: [], topFrame: [], focusedFrame: [] };
    }
    const lineAt = {};
    for (const n of editor.querySelectorAll('.margin-view-overlays .line-numbers')) {
      lineAt[n.parentElement.style.top] = parseInt(n.textContent, 10);
    }
    const at = (el) => (el.style.top in lineAt ? lineAt[el.style.top] : null);
    const lines = (cls) => [...editor.querySelectorAll(`.view-overlays .${cls}`)].map((d) => at(d.parentElement));
    return {
      glyphs: [...editor.querySelectorAll('.glyph-margin-widgets > div')].map((g) => ({
        line: at(g),
        icons: [...g.classList].filter((c) => c.startsWith('codicon-')),
      })),
      topFrame: lines('debug-top-stack-frame-line'),
      focusedFrame: lines('debug-focused-stack-frame-line'),
    };
  });
}

const rows = (page, view) =>
  page.$$eval(`${view} .monaco-list-row`, (els) =>
    els.map((e) => ({ label: e.getAttribute('aria-label') || '', expanded: e.getAttribute('aria-expanded') })),
  );

/** The debug toolbar: null when no session, else whether it offers Continue (stopped) or Pause. */
async function toolbar(page) {
  return page.evaluate(() => {
    const bar = document.querySelector('.debug-toolbar');
    if (!bar || bar.offsetParent === null) {
      return null;
    }
    return {
      continue: !!bar.querySelector('.codicon-debug-continue'),
      pause: !!bar.querySelector('.codicon-debug-pause'),
    };
  });
}

/** The Call Stack's title: the reason of the stop (the `stopped` event's description). */
async function callStackTitle(page) {
  return page.$$eval('.pane-header', (headers) =>
    headers.map((h) => h.textContent.trim()).filter((t) => /^call stack/i.test(t)),
  );
}

async function snapshot(page) {
  return {
    toolbar: await toolbar(page),
    ...(await gutter(page)),
    callStackTitle: await callStackTitle(page),
    callStack: (await rows(page, '.debug-call-stack')).map((r) => r.label),
    breakpoints: (await rows(page, '.debug-breakpoints')).map((r) => r.label),
  };
}

/** Stopped at config.line: toolbar's Continue, the frame's glyph and highlight there, frames listed. */
function stoppedThere(s) {
  const glyph = s.glyphs.find((g) => g.line === config.line);
  return (
    s.toolbar &&
    s.toolbar.continue &&
    glyph &&
    glyph.icons.includes('codicon-debug-stackframe') &&
    s.topFrame.includes(config.line) &&
    s.callStack.some((f) => f.startsWith('Stack Frame ')) &&
    // The frames below the top one come a moment later (delayed stack trace loading).
    !s.callStack.some((f) => f.startsWith('Load More'))
  );
}

/** The value of `counter` in the main tree's blackboard (expanding "All blackboards" and it). */
async function counter(page) {
  for (const [name, label] of [
    ['all', 'Scope All blackboards'],
    ['main', `${config.mainTree}, value`],
  ]) {
    const row = (await rows(page, '.debug-variables')).find((r) => r.label.startsWith(label));
    if (!row) {
      return { missing: name };
    }
    if (row.expanded === 'false') {
      await page.click(`.debug-variables .monaco-list-row[aria-label^="${label}"]`);
    }
  }
  const entry = await until(async () => {
    const found = (await rows(page, '.debug-variables')).find((r) => r.label.startsWith('counter, value '));
    return found ? found.label : null;
  }, 5000, 100);
  return entry ? { value: parseInt(entry.slice('counter, value '.length), 10) } : { missing: 'counter' };
}

/** Waits for a stop at config.line whose counter is above `above`; the snapshot with the variables. */
async function waitStop(page, above) {
  const stop = await until(async () => {
    const s = await snapshot(page);
    if (!stoppedThere(s)) {
      return null;
    }
    const c = await counter(page);
    if (c.value === undefined || c.value <= above) {
      return null;
    }
    s.counter = c.value;
    s.variables = (await rows(page, '.debug-variables')).map((r) => r.label);
    return s;
  }, SERVER_TIMEOUT, 200);
  if (!stop) {
    result.lastSeen = await snapshot(page);
    throw new Error(`VS Code did not stop at line ${config.line} (counter above ${above})`);
  }
  return stop;
}

/** The Debug Console's lines (the adapter's output events). */
async function replLines(page) {
  return page.$$eval('.repl .monaco-list-row', (els) => els.map((e) => e.innerText.trim()));
}

async function editorFocus(page) {
  await page.click('.editor-instance .monaco-editor .view-lines');
}

async function command(page, title) {
  await editorFocus(page);
  await page.keyboard.press('F1');
  await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
  await page.keyboard.type(title);
  await page.waitForSelector(`.quick-input-list .monaco-list-row[aria-label*="${title.replace('bt-lsp: ', '')}"]`, {
    timeout: STEP_TIMEOUT,
  });
  await page.keyboard.press('Enter');
}

/** Shift+F5; waits until no debug session is left. */
async function stopDebugging(page) {
  await editorFocus(page);
  await page.keyboard.press('Shift+F5');
  const gone = await until(async () => (await toolbar(page)) === null, STEP_TIMEOUT, 200);
  if (!gone) {
    throw new Error('the debug toolbar is still there after Shift+F5');
  }
  return snapshot(page);
}

async function main(page) {
  mark('executor');
  const { record: first, child: firstChild } = await startExecutor();

  mark('load workbench');
  await loadWorkbench(page, config.file);
  await openFile(page, config.file);

  mark('breakpoint (F9)');
  await editorFocus(page);
  await gotoPosition(page, config.line, 1);
  await page.keyboard.press('F9');
  result.breakpointSet = await until(async () => {
    const s = await snapshot(page);
    return s.glyphs.some((g) => g.line === config.line && g.icons.includes('codicon-debug-breakpoint')) ? s : null;
  }, STEP_TIMEOUT, 100);
  if (!result.breakpointSet) {
    throw new Error('no breakpoint glyph after F9');
  }

  mark('start debugging (F5)');
  await page.keyboard.press('F5');
  result.stopped = await waitStop(page, -1);
  result.stoppedAt = first.lines.length;
  mark('stopped');
  await page.screenshot({ path: path.join(config.shotDir, 'debug.png') });
  result.console = await replLines(page);

  mark('select the main tree\'s frame');
  await page.click(`.debug-call-stack .monaco-list-row[aria-label^='Stack Frame ${config.mainFrame}']`);
  result.mainFrame = await until(async () => {
    const variables = (await rows(page, '.debug-variables')).map((r) => r.label);
    const s = await gutter(page);
    return variables[0] === `Scope Blackboard ${config.mainTree}` && s.focusedFrame.length
      ? { variables, ...s }
      : null;
  }, STEP_TIMEOUT, 200);
  if (!result.mainFrame) {
    result.lastSeen = await snapshot(page);
    throw new Error(`selecting ${config.mainFrame} did not show its blackboard`);
  }

  mark('fail node');
  // Results printed while the tree waited at the breakpoint (none expected).
  result.whileStopped = resultsFrom(first, result.stoppedAt);
  const beforeFail = first.lines.length;
  await command(page, 'bt-lsp: Fail node');
  result.afterFail = (await waitResults(first, beforeFail, 1, 'result after Fail node'))[0];
  result.stoppedAfterFail = await waitStop(page, result.stopped.counter);

  mark('continue');
  const beforeContinue = first.lines.length;
  await page.click('.debug-toolbar .codicon-debug-continue');
  result.afterContinue = (await waitResults(first, beforeContinue, 1, 'result after Continue'))[0];
  result.stoppedAfterContinue = await waitStop(page, result.stoppedAfterFail.counter);

  mark('stop debugging');
  const beforeStop = first.lines.length;
  result.stoppedDebugging = await stopDebugging(page);
  result.afterStop = await waitResults(first, beforeStop, 3, 'three results after Shift+F5');
  result.consoleAfterStop = await replLines(page);

  mark('executor stopped');
  firstChild.kill('SIGKILL');
  await until(() => result.executors[0].exit !== null, STEP_TIMEOUT, 100);

  mark('start debugging without an executor (F5)');
  await editorFocus(page);
  await page.keyboard.press('F5');
  result.pending = await until(async () => {
    const s = await snapshot(page);
    const glyph = s.glyphs.find((g) => g.line === config.line);
    return s.toolbar && glyph && glyph.icons.includes('codicon-debug-breakpoint-unverified') &&
      s.breakpoints.some((b) => b.includes('pending')) ? s : null;
  }, SERVER_TIMEOUT, 200);
  if (!result.pending) {
    result.lastSeen = await snapshot(page);
    throw new Error('the breakpoint is not shown pending while no executor runs');
  }
  result.pendingConsole = await until(async () => {
    const lines = await replLines(page);
    return lines.some((l) => l.includes('waiting for the executor')) ? lines : null;
  }, STEP_TIMEOUT, 200);
  await page.screenshot({ path: path.join(config.shotDir, 'debug-pending.png') });

  mark('executor started');
  const { record: second } = await startExecutor();
  result.secondReadyAt = second.lines[0].atMs;
  result.stoppedLater = await waitStop(page, -1);
  result.stoppedLaterAt = Date.now() - started;

  mark('stop debugging again');
  const beforeStopAgain = second.lines.length;
  result.stoppedDebuggingAgain = await stopDebugging(page);
  result.afterStopAgain = await waitResults(second, beforeStopAgain, 3, 'three results after Shift+F5');
  mark('done');
}

process.on('exit', () => {
  for (const child of children) {
    if (child.exitCode === null && child.signalCode === null) {
      child.kill('SIGKILL');
    }
  }
});

run(main, { viewport: { width: 1400, height: 800 }, failureShot: 'debug-failure.png' });
