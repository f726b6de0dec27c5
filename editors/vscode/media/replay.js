// The timeline of "bt-lsp: Replay a .btlog": buttons, a slider over the log's transitions and a
// speed; the extension keeps the clock and shows the statuses, this page only asks and shows
// where the replay is. No eval, no remote content: the CSP allows this script by nonce only.
(function () {
  'use strict';
  const vscode = acquireVsCodeApi();
  const $ = (id) => document.getElementById(id);
  const timeline = $('timeline');
  const play = $('play');
  let playing = false;
  let count = parseInt(timeline.max, 10) || 0;

  function seek(applied) {
    vscode.postMessage({ type: 'seek', applied: Math.max(0, Math.min(count, applied)) });
  }

  $('start').addEventListener('click', () => seek(0));
  $('end').addEventListener('click', () => seek(count));
  $('back').addEventListener('click', () => vscode.postMessage({ type: 'step', delta: -1 }));
  $('forward').addEventListener('click', () => vscode.postMessage({ type: 'step', delta: 1 }));
  play.addEventListener('click', () => vscode.postMessage({ type: playing ? 'pause' : 'play' }));
  $('stop').addEventListener('click', () => vscode.postMessage({ type: 'stop' }));
  $('speed').addEventListener('change', (event) =>
    vscode.postMessage({ type: 'speed', speed: parseFloat(event.target.value) }),
  );
  timeline.addEventListener('input', () => seek(parseInt(timeline.value, 10) || 0));

  document.addEventListener('keydown', (event) => {
    if (event.target instanceof HTMLSelectElement) {
      return;
    }
    const keys = {
      ' ': () => vscode.postMessage({ type: playing ? 'pause' : 'play' }),
      ArrowLeft: () => vscode.postMessage({ type: 'step', delta: -1 }),
      ArrowRight: () => vscode.postMessage({ type: 'step', delta: 1 }),
      Home: () => seek(0),
      End: () => seek(count),
    };
    if (keys[event.key]) {
      event.preventDefault();
      keys[event.key]();
    }
  });

  window.addEventListener('message', (event) => {
    const m = event.data;
    if (m.type === 'ended') {
      playing = false;
      document.body.dataset.ended = 'true';
      $('where').textContent = 'The replay ended.';
      $('last').textContent = '';
      return;
    }
    if (m.type !== 'state') {
      return;
    }
    delete document.body.dataset.ended;
    count = m.count;
    timeline.max = String(m.count);
    timeline.value = String(m.applied);
    playing = m.playing;
    play.textContent = playing ? '||' : '▶';
    play.setAttribute('aria-label', playing ? 'Pause' : 'Play');
    $('where').textContent =
      m.name + ' · ' + m.time + ' · transition ' + m.applied + ' of ' + m.count + ' · started ' + m.started;
    $('last').textContent = m.last;
    document.body.dataset.applied = String(m.applied);
    document.body.dataset.playing = String(playing);
  });

  vscode.postMessage({ type: 'ready' });
})();
