// The webview of "bt-lsp: Show Tree": shows the SVG the server drew, pans and zooms it (mouse and
// keyboard), opens each tree fitted to the view, keeps the zoom and scroll across updates of the
// same tree (or the fit, until the user zooms or pans) and scrolls the node an edit made or
// changed into view, highlights the node the extension names, colours each node with the status
// of its running node while the server watches a running tree (classes live-running,
// live-success, live-failure, live-idle, live-skipped; each picture comes with its nodes'
// statuses, and 'live' messages update them), and reports clicks. No eval, no
// remote content: the CSP allows this script and styles carrying the page's nonce only.
(function () {
  'use strict';
  const vscode = acquireVsCodeApi();
  const view = document.getElementById('view');
  const canvas = document.getElementById('canvas');
  const title = document.getElementById('title');
  const status = document.getElementById('status');
  const nonce = canvas.dataset.nonce;
  const MIN_ZOOM = 0.05; // unless fitting the whole tree takes less
  const MAX_ZOOM = 8;
  const MARGIN = 16;

  // fitted: the view shows the whole tree and follows its size until the user zooms or pans.
  let state = Object.assign({ x: 16, y: 16, k: 1, tree: null, fitted: false }, vscode.getState() || {});
  let selected = null;
  let size = { w: 0, h: 0 };
  let drag = null;
  // The live status of each node drawn, by SVG id, from the extension's last 'live' message.
  let live = {};
  const LIVE = ['idle', 'running', 'success', 'failure', 'skipped'];
  const LIVE_CLASSES = LIVE.map((s) => 'live-' + s);

  function applyLive() {
    let count = 0;
    for (const g of canvas.querySelectorAll('g.node')) {
      const status = Object.prototype.hasOwnProperty.call(live, g.id) ? live[g.id] : null;
      g.classList.remove(...LIVE_CLASSES);
      if (LIVE.includes(status)) {
        g.classList.add('live-' + status);
        count++;
      }
    }
    document.body.dataset.live = String(count);
    document.body.classList.toggle('live', count > 0);
  }

  function apply() {
    canvas.style.transform = 'translate(' + state.x + 'px, ' + state.y + 'px) scale(' + state.k + ')';
    vscode.setState(state);
  }

  /** The zoom at which the whole tree fits the view (at most 1: a small tree is not blown up). */
  function fitScale() {
    const w = view.clientWidth - 2 * MARGIN;
    const h = view.clientHeight - 2 * MARGIN;
    if (!size.w || !size.h || w <= 0 || h <= 0) {
      return null;
    }
    return Math.min(1, w / size.w, h / size.h);
  }

  /** The whole tree in view, centred (so that zooming in at the middle stays on the tree). */
  function fit() {
    const k = fitScale();
    if (k === null) {
      return;
    }
    state.k = k;
    state.x = (view.clientWidth - size.w * k) / 2;
    state.y = (view.clientHeight - size.h * k) / 2;
    state.fitted = true;
    apply();
  }

  function zoomAt(factor, mx, my) {
    const fitted = fitScale();
    const min = fitted === null ? MIN_ZOOM : Math.min(MIN_ZOOM, fitted);
    const k = Math.min(MAX_ZOOM, Math.max(min, state.k * factor));
    state.fitted = false;
    state.x = mx - ((mx - state.x) * k) / state.k;
    state.y = my - ((my - state.y) * k) / state.k;
    state.k = k;
    apply();
  }

  function select(id, scroll) {
    if (selected) {
      selected.classList.remove('selected');
    }
    selected = id ? document.getElementById(id) : null;
    if (!selected) {
      return;
    }
    selected.classList.add('selected');
    if (scroll) {
      const box = selected.getBoundingClientRect();
      const outer = view.getBoundingClientRect();
      if (box.right < outer.left || box.left > outer.right || box.bottom < outer.top || box.top > outer.bottom) {
        state.x += outer.left + outer.width / 2 - (box.left + box.width / 2);
        state.y += outer.top + outer.height / 3 - (box.top + box.height / 2);
        state.fitted = false;
        apply();
      }
    }
  }

  /** The shift along one axis that brings [lo, hi] inside [min, max] (its start, if too long). */
  function shiftInto(lo, hi, min, max) {
    if (lo < min || hi - lo > max - min) {
      return min - lo;
    }
    return hi > max ? max - hi : 0;
  }

  /** Pans, as little as it takes, until node ``id`` is wholly in view (keeping the zoom). */
  function keepInView(id) {
    const node = id ? document.getElementById(id) : null;
    if (!node) {
      return;
    }
    const box = node.getBoundingClientRect();
    const outer = view.getBoundingClientRect();
    const dx = shiftInto(box.left, box.right, outer.left + MARGIN, outer.right - MARGIN);
    const dy = shiftInto(box.top, box.bottom, outer.top + MARGIN, outer.bottom - MARGIN);
    if (dx || dy) {
      state.x += dx;
      state.y += dy;
      state.fitted = false;
      apply();
    }
  }

  function render(message) {
    // The SVG's own style sheet may run under the page's CSP only with its nonce.
    canvas.innerHTML = message.svg.replace('<style>', '<style nonce="' + nonce + '">');
    const svg = canvas.querySelector('svg');
    size = { w: parseFloat(svg.getAttribute('width')) || 0, h: parseFloat(svg.getAttribute('height')) || 0 };
    title.textContent = message.tree;
    status.textContent = message.nodes.length - 1 + ' nodes';
    selected = null;
    if (state.tree !== message.tree) {
      state.tree = message.tree;
      state.fitted = true; // a new tree opens fitted (and is fitted when the view gets a size)
    }
    if (state.fitted) {
      fit();
    } else {
      apply();
      keepInView(message.changed);
    }
    select(message.selected, false);
    live = message.live && typeof message.live === 'object' ? message.live : {};
    applyLive();
    document.body.dataset.tree = message.tree;
    document.body.dataset.renders = String((parseInt(document.body.dataset.renders || '0', 10) || 0) + 1);
  }

  window.addEventListener('message', (event) => {
    const message = event.data;
    if (message.type === 'render') {
      render(message);
    } else if (message.type === 'live') {
      live = message.statuses && typeof message.statuses === 'object' ? message.statuses : {};
      applyLive();
    } else if (message.type === 'highlight') {
      select(message.id, true);
    } else if (message.type === 'message') {
      status.textContent = message.text;
      if (/^No </.test(message.text)) {
        canvas.textContent = '';
        title.textContent = '';
      }
    }
  });

  view.addEventListener('wheel', (event) => {
    event.preventDefault();
    const outer = view.getBoundingClientRect();
    zoomAt(Math.exp(-event.deltaY * 0.0015), event.clientX - outer.left, event.clientY - outer.top);
  }, { passive: false });

  view.addEventListener('pointerdown', (event) => {
    if (event.button !== 0) {
      return;
    }
    drag = { x: event.clientX, y: event.clientY, moved: false };
    view.setPointerCapture(event.pointerId);
  });
  view.addEventListener('pointermove', (event) => {
    if (!drag) {
      return;
    }
    const dx = event.clientX - drag.x;
    const dy = event.clientY - drag.y;
    if (!drag.moved && Math.abs(dx) + Math.abs(dy) < 4) {
      return;
    }
    drag.moved = true;
    view.classList.add('panning');
    state.x += dx;
    state.y += dy;
    state.fitted = false;
    drag.x = event.clientX;
    drag.y = event.clientY;
    apply();
  });
  view.addEventListener('pointerup', (event) => {
    const wasDrag = drag && drag.moved;
    drag = null;
    view.classList.remove('panning');
    if (wasDrag) {
      return;
    }
    const node = document.elementFromPoint(event.clientX, event.clientY);
    const g = node && node.closest ? node.closest('g.node') : null;
    if (g) {
      select(g.id, false);
      vscode.postMessage({ type: 'reveal', id: g.id });
    }
  });
  view.addEventListener('dblclick', (event) => {
    const node = document.elementFromPoint(event.clientX, event.clientY);
    const g = node && node.closest ? node.closest('g.node') : null;
    if (g && g.dataset.subtree) {
      vscode.postMessage({ type: 'open', id: g.id });
    }
  });

  function pan(dx, dy) {
    state.x += dx;
    state.y += dy;
    state.fitted = false;
    apply();
  }

  view.addEventListener('keydown', (event) => {
    const step = 48;
    const w = view.clientWidth / 2;
    const h = view.clientHeight / 2;
    switch (event.key) {
      case '+':
      case '=':
        zoomAt(1.2, w, h);
        break;
      case '-':
      case '_':
        zoomAt(1 / 1.2, w, h);
        break;
      case '0':
        fit();
        break;
      case 'ArrowLeft':
        pan(step, 0);
        break;
      case 'ArrowRight':
        pan(-step, 0);
        break;
      case 'ArrowUp':
        pan(0, step);
        break;
      case 'ArrowDown':
        pan(0, -step);
        break;
      case 'Enter':
        if (selected) {
          vscode.postMessage({ type: selected.dataset.subtree ? 'open' : 'reveal', id: selected.id });
        }
        break;
      default:
        return;
    }
    event.preventDefault();
  });

  const ports = document.getElementById('ports');
  const expand = document.getElementById('expand');
  ports.checked = state.ports === true;
  expand.checked = state.expandSubtrees === true;
  function options() {
    state.ports = ports.checked;
    state.expandSubtrees = expand.checked;
    vscode.setState(state);
    vscode.postMessage({ type: 'options', ports: ports.checked, expandSubtrees: expand.checked });
  }
  ports.addEventListener('change', options);
  expand.addEventListener('change', options);

  window.addEventListener('resize', () => (state.fitted ? fit() : apply()));
  apply();
  vscode.postMessage({ type: 'ready' });
  if (ports.checked || expand.checked) {
    options();
  }
})();
