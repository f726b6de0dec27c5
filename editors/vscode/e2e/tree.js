#!/usr/bin/env node
// Drives "bt-lsp: Show Tree" in a running code-server (with the bt-lsp extension installed) from
// headless Chromium and prints what a user would see as one JSON object on the last line of stdout.
//
//   node tree.js '{"url": "http://127.0.0.1:PORT/?folder=/ws", "file": "mission.xml",
//                  "insertAt": [5, 7], "insert": "<AlwaysFailure/>", "expectType": "AlwaysFailure",
//                  "clickType": "Fallback", "cursorAt": [4, 10], "cursorType": "Charge",
//                  "subtreeType": "Dock", "subtreeTree": "Dock", "shotDir": "/tmp/shots"}'
//
// Steps: open the file, wait for the server (its first squiggle), run "bt-lsp: Show Tree" from the
// Command Palette, read the picture's nodes in the webview (and whether it opened fitted); type
// `insert` at line:column insertAt and wait for the picture to show a node of type expectType;
// click the node of type clickType and read the editor's selection from the status bar; zoom with
// the keyboard; move the cursor to cursorAt and read which node the webview highlights; check
// that an update keeps the zoom; zoom far in and type `add` at addAt, then read whether the new
// node of type addType is in view; tick "expand SubTrees" (a node of type expandedType appears)
// and "ports" (blackboard keys appear); double-click the SubTree node of type subtreeType and wait
// for the picture of subtreeTree; with `big`, open its file and check that its tree is drawn in
// full and opened fitted.
// Screenshots: tree.png (after the click), tree-failure.png on failure, in shotDir.
// Exit status: 0 when every step ran (the caller judges the result), 1 when one failed.

'use strict';

const path = require('node:path');
const { driver } = require('./workbench');

const config = JSON.parse(process.argv[2] || '{}');
const { STEP_TIMEOUT, SERVER_TIMEOUT, result, mark, until, gotoPosition, openFile, loadWorkbench, run } = driver(
  'tree',
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

/** What the webview shows: its tree, node types in order, the highlighted one, the zoom. */
async function picture(frame) {
  return frame.evaluate(() => {
    const nodes = [...document.querySelectorAll('#canvas g.node')];
    const selected = document.querySelector('#canvas g.node.selected');
    return {
      tree: document.body.dataset.tree || null,
      renders: parseInt(document.body.dataset.renders || '0', 10),
      types: nodes.map((g) => g.dataset.type),
      kinds: nodes.map((g) => g.dataset.kind),
      badges: nodes.filter((g) => /\bsev-/.test(g.getAttribute('class'))).map((g) => g.dataset.type),
      selected: selected ? selected.dataset.type : null,
      transform: document.getElementById('canvas').style.transform,
      // The SVG's style sheet applied (the CSP let it in): a node outline has its kind's colour.
      stroke: nodes.length ? getComputedStyle(nodes[1].querySelector('.shape')).stroke : null,
      status: document.getElementById('status').textContent,
      keys: [...document.querySelectorAll('#canvas tspan.key')].map((t) => t.textContent),
      // The node types wholly in view, and whether all of the picture is.
      inView: nodes.filter((g) => inside(g)).map((g) => g.dataset.type),
      fits: inside(document.querySelector('#canvas svg')),
    };
    function inside(el) {
      if (!el) {
        return false;
      }
      const r = el.getBoundingClientRect();
      const v = document.getElementById('view').getBoundingClientRect();
      return r.left >= v.left - 1 && r.right <= v.right + 1 && r.top >= v.top - 1 && r.bottom <= v.bottom + 1;
    }
  });
}

async function selectionStatus(page) {
  return page
    .$eval('.statusbar-item[id="status.editor.selection"]', (el) => el.innerText.trim())
    .catch(() => '');
}

async function main(page) {
  mark('load workbench');
  await loadWorkbench(page, config.file);

  mark('open file');
  await openFile(page, config.file);
  await page.keyboard.press('Control+B'); // the side bar away: room for the editor and the tree

  mark('wait for the server');
  result.squiggle = await page
    .waitForSelector('.editor-instance .squiggly-error', { timeout: SERVER_TIMEOUT })
    .then(() => true, () => false);
  if (!result.squiggle) {
    throw new Error(`no error squiggle within ${SERVER_TIMEOUT} ms (is the server running?)`);
  }
  result.titleButton = await page
    .$$eval('.editor-actions .action-label', (els) => els.map((e) => e.getAttribute('aria-label') || ''))
    .then((labels) => labels.some((l) => l.includes('Show Tree')))
    .catch(() => false);

  mark('show tree');
  await page.click('.editor-instance .monaco-editor .view-lines');
  await page.keyboard.press('F1');
  await page.waitForSelector('.quick-input-widget input', { state: 'visible', timeout: STEP_TIMEOUT });
  await page.keyboard.type('bt-lsp: Show Tree');
  await page.waitForSelector('.quick-input-list .monaco-list-row[aria-label*="Show Tree"]', { timeout: STEP_TIMEOUT });
  await page.keyboard.press('Enter');
  const frame = await until(() => treeFrame(page), STEP_TIMEOUT, 300);
  if (!frame) {
    throw new Error('no tree webview appeared');
  }
  result.first = await until(async () => {
    const p = await picture(frame);
    return p.types.length > 0 ? p : null;
  }, SERVER_TIMEOUT);
  if (!result.first) {
    throw new Error('the webview shows no tree');
  }

  mark('edit');
  await page.click('.editor-instance .monaco-editor .view-lines');
  await gotoPosition(page, config.insertAt[0], config.insertAt[1]);
  await page.keyboard.type(config.insert);
  result.afterEdit = await until(async () => {
    const p = await picture(frame);
    return p.types.includes(config.expectType) ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));

  mark('click a node');
  await frame.click(`#canvas g.node[data-type="${config.clickType}"]`);
  // The status bar may first show an older selection: wait for the clicked node's.
  result.selection = await until(async () => {
    const s = await selectionStatus(page);
    return /selected/.test(s) && (!config.selectionAt || s.includes(config.selectionAt)) ? s : null;
  }, STEP_TIMEOUT) || (await selectionStatus(page));
  await new Promise((resolve) => setTimeout(resolve, 500));
  await page.screenshot({ path: path.join(config.shotDir, 'tree.png') });

  mark('zoom');
  const before = (await picture(frame)).transform;
  await frame.focus('#view');
  await page.keyboard.press('-');
  await page.keyboard.press('-');
  result.zoomBefore = before;
  result.zoomed = (await picture(frame)).transform;

  mark('mouse');
  // The wheel zooms at the pointer, a drag on the background pans.
  const area = await (await frame.$('#view')).boundingBox();
  await page.mouse.move(area.x + area.width * 0.8, area.y + area.height * 0.8);
  const beforeWheel = (await picture(frame)).transform;
  await page.mouse.wheel(0, -240);
  result.wheel = await until(async () => {
    const t = (await picture(frame)).transform;
    return t !== beforeWheel ? { before: beforeWheel, after: t } : null;
  }, STEP_TIMEOUT, 100) || { before: beforeWheel, after: beforeWheel };
  await page.mouse.down();
  await page.mouse.move(area.x + area.width * 0.8 - 60, area.y + area.height * 0.8 - 40, { steps: 6 });
  await page.mouse.up();
  result.drag = { before: result.wheel.after, after: (await picture(frame)).transform };

  mark('move the cursor');
  await page.click('.editor-instance .monaco-editor .view-lines');
  await gotoPosition(page, config.cursorAt[0], config.cursorAt[1]);
  result.highlighted = await until(async () => {
    const p = await picture(frame);
    return p.selected === config.cursorType ? p.selected : null;
  }, STEP_TIMEOUT) || (await picture(frame)).selected;

  mark('update keeps the zoom');
  const beforeSecond = await picture(frame);
  const renders = beforeSecond.renders;
  result.transformBeforeSecondEdit = beforeSecond.transform;
  await page.keyboard.press('End');
  await page.keyboard.type(' ');
  result.afterSecondEdit = await until(async () => {
    const p = await picture(frame);
    return p.renders > renders ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));

  mark('a node added out of view');
  // Fitted, then zoomed far in at the middle: the end of the tree's top rows is out of view.
  await frame.focus('#view');
  await page.keyboard.press('0');
  for (let i = 0; i < 8; i++) {
    await page.keyboard.press('+');
  }
  const zoomedIn = await picture(frame);
  result.beforeAdd = { transform: zoomedIn.transform, inView: zoomedIn.inView };
  await page.click('.editor-instance .monaco-editor .view-lines');
  await gotoPosition(page, config.addAt[0], config.addAt[1]);
  await page.keyboard.type(config.add);
  result.added = await until(async () => {
    const p = await picture(frame);
    return p.inView.includes(config.addType) ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));
  await frame.focus('#view');
  await page.keyboard.press('0'); // all of it in view again for the next steps

  mark('expand and ports');
  await frame.click('#expand');
  result.expanded = await until(async () => {
    const p = await picture(frame);
    return p.types.includes(config.expandedType) ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));
  await frame.click('#ports');
  result.withPorts = await until(async () => {
    const p = await picture(frame);
    return p.keys.length > 0 ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));

  mark('open a subtree');
  await frame.dblclick(`#canvas g.node[data-type="${config.subtreeType}"]`);
  result.subtree = await until(async () => {
    const p = await picture(frame);
    return p.tree === config.subtreeTree ? p : null;
  }, STEP_TIMEOUT) || (await picture(frame));
  result.subtreeSelection = await selectionStatus(page);
  if (config.big) {
    // A large tree: the view follows the newly active editor and draws every node.
    mark('big tree');
    await page.click('.editor-instance .monaco-editor .view-lines');
    const t0 = Date.now();
    await openFile(page, config.big.file);
    const big = await until(async () => {
      const p = await picture(frame);
      return p.types.length === config.big.nodes + 1 ? p : null;
    }, SERVER_TIMEOUT, 100);
    result.big = { nodes: big ? big.types.length : (await picture(frame)).types.length, shownMs: Date.now() - t0 };
    await frame.focus('#view');
    // Opened fitted, all of it in view; '0' fits it again, '+' zooms in.
    const opened = await picture(frame);
    result.big.initialTransform = opened.transform;
    result.big.fits = opened.fits;
    const z0 = Date.now();
    await page.keyboard.press('0');
    result.big.fittedTransform = (await picture(frame)).transform;
    result.big.fitMs = Date.now() - z0;
    await page.keyboard.press('+');
    result.big.zoomedTransform = (await picture(frame)).transform;
    await page.keyboard.press('0');
    // Zoomed in to where a node is large enough to click.
    for (let i = 0; i < 40; i++) {
      const t = (await picture(frame)).transform;
      const k = parseFloat((/scale\(([\d.e-]+)\)/.exec(t) || [])[1] || '1');
      if (k >= 0.3) {
        break;
      }
      await page.keyboard.press('+');
    }
    // The last node in view (drawn in pre-order: the deepest visible one on the right).
    const target = await frame.$$eval('#canvas g.node', (gs) => {
      const view = document.getElementById('view').getBoundingClientRect();
      const inside = gs.filter((g) => {
        const r = g.getBoundingClientRect();
        return r.left >= view.left && r.right <= view.right && r.top >= view.top && r.bottom <= view.bottom;
      });
      return inside.length ? inside[inside.length - 1].id : null;
    });
    if (!target) {
      throw new Error('no node of the large tree in view after fitting it');
    }
    result.big.clicked = target;
    const c0 = Date.now();
    await frame.click(`#canvas g[id="${target}"]`);
    result.big.selection = await until(async () => {
      const s = await selectionStatus(page);
      return /selected/.test(s) ? s : null;
    }, STEP_TIMEOUT, 50) || (await selectionStatus(page));
    result.big.clickToSelectionMs = Date.now() - c0;
  }
  mark('done');
}

run(main, { viewport: { width: 1400, height: 800 }, failureShot: 'tree-failure.png' });
