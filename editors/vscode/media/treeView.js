// The webview of "bt-lsp: Show Tree": shows the SVG the server drew, pans and zooms it (mouse and
// keyboard), keeps the zoom and scroll across updates of the same tree, highlights the node the
// extension names, and reports clicks. No eval, no remote content: the CSP allows this script and
// styles carrying the page's nonce only.
(function () {
  'use strict';
  const vscode = acquireVsCodeApi();
  const view = document.getElementById('view');
  const canvas = document.getElementById('canvas');
  const title = document.getElementById('title');
  const status = document.getElementById('status');
  const nonce = canvas.dataset.nonce;
  const MIN_ZOOM = 0.05;
  const MAX_ZOOM = 8;

  let state = Object.assign({ x: 16, y: 16, k: 1, tree: null }, vscode.getState() || {});
  let selected = null;
  let size = { w: 0, h: 0 };
  let drag = null;

  function apply() {
    canvas.style.transform = 'translate(' + state.x + 'px, ' + state.y + 'px) scale(' + state.k + ')';
    vscode.setState(state);
  }

  function fit() {
    const w = view.clientWidth;
    const h = view.clientHeight;
    if (!size.w || !w) {
      return;
    }
    state.k = Math.max(MIN_ZOOM, Math.min(1, (w - 32) / size.w, Math.max((h - 32) / size.h, 0.35)));
    state.x = Math.max(16, (w - size.w * state.k) / 2);
    state.y = 16;
    apply();
  }

  /** A new tree: all of it when it fits at a readable size, else its top, root centred. */
  function initial() {
    const w = view.clientWidth;
    if (!size.w || !w) {
      return;
    }
    const k = Math.min(1, (w - 32) / size.w, Math.max((view.clientHeight - 32) / size.h, 0.5));
    if (k >= 0.5) {
      fit();
      return;
    }
    state.k = 0.5;
    state.x = w / 2 - (size.w / 2) * state.k;
    state.y = 16;
    apply();
  }

  function zoomAt(factor, mx, my) {
    const k = Math.min(MAX_ZOOM, Math.max(MIN_ZOOM, state.k * factor));
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
        apply();
      }
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
      initial();
    } else {
      apply();
    }
    select(message.selected, false);
    document.body.dataset.tree = message.tree;
    document.body.dataset.renders = String((parseInt(document.body.dataset.renders || '0', 10) || 0) + 1);
  }

  window.addEventListener('message', (event) => {
    const message = event.data;
    if (message.type === 'render') {
      render(message);
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
        state.x += step;
        apply();
        break;
      case 'ArrowRight':
        state.x -= step;
        apply();
        break;
      case 'ArrowUp':
        state.y += step;
        apply();
        break;
      case 'ArrowDown':
        state.y -= step;
        apply();
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

  window.addEventListener('resize', () => apply());
  apply();
  vscode.postMessage({ type: 'ready' });
  if (ports.checked || expand.checked) {
    options();
  }
})();
