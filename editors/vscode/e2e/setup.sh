#!/usr/bin/env bash
# Installs what the VS Code end-to-end test (tests/e2e/test_vscode.py) needs. Idempotent: what is
# already there is kept. Needs python3, Node 20 and npm, and reaches only the Debian, npm and
# Python package registries.
#
#   1. Debian packages: chromium (the browser that drives VS Code), and what code-server's
#      native modules build from: build-essential, pkg-config, libkrb5-dev; ripgrep (VS Code's
#      search, whose npm package would download its binary from elsewhere).
#   2. The extension: `npm ci` and `npm run package` in editors/vscode -> bt-lsp.vsix; and the
#      package for this machine that brings its own server, with bt-lsp and its dependencies
#      as wheels (scripts/vscode_bundle.py; wheels cached in editors/vscode/.wheels-cache)
#      -> bt-lsp-linux-x64.vsix (tests/e2e/test_vscode_bundled.py).
#   3. code-server 4.100.3 (VS Code 1.100.3, the last release that runs on Node 20) into
#      editors/vscode/.e2e/code-server, with its install script redone here so that native
#      modules are built from source against the local Node headers and nothing is downloaded
#      from outside the npm registry.
#   4. playwright-core into editors/vscode/e2e/node_modules (e2e/package.json and its lock).
set -euo pipefail

CODE_SERVER_VERSION=4.100.3
E2E_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
EXT_DIR=$(dirname "$E2E_DIR")
REPO_DIR=$(dirname "$(dirname "$EXT_DIR")")
CS_DIR="$EXT_DIR/.e2e/code-server"
CS_MARKER="$CS_DIR/.installed-$CODE_SERVER_VERSION"

say() { printf '\n== %s\n' "$*"; }

# `npm ci` in $1, skipped when node_modules was installed from the same package-lock.json.
npm_ci() {
  local stamp="$1/node_modules/.bt-lsp-installed-lock.json"
  if cmp -s "$1/package-lock.json" "$stamp"; then
    echo "$1: node_modules is up to date with package-lock.json"
  else
    (cd "$1" && npm ci)
    cp "$1/package-lock.json" "$stamp"
  fi
}

# --- 1. Debian packages -------------------------------------------------------------------
apt_packages=(chromium build-essential pkg-config libkrb5-dev ripgrep python3)
missing=()
for pkg in "${apt_packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$pkg")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  say "apt-get install ${missing[*]}"
  SUDO=()
  [ "$(id -u)" -eq 0 ] || SUDO=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  # A fresh machine has no package lists yet; an old list may name versions that are gone.
  "${SUDO[@]}" apt-get update
  "${SUDO[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
else
  say "Debian packages: already installed (${apt_packages[*]})"
fi

# Node's headers, so that node-gyp builds native modules without downloading them.
NODE_PREFIX=$(dirname "$(dirname "$(readlink -f "$(command -v node)")")")
if [ ! -f "$NODE_PREFIX/include/node/node.h" ]; then
  echo "setup.sh: Node's C headers are not in $NODE_PREFIX/include/node (install a Node 20 that ships them)" >&2
  exit 1
fi
export npm_config_nodedir="$NODE_PREFIX"
export npm_config_yes=true          # `npx node-gyp` without a prompt
export npm_config_audit=false npm_config_fund=false npm_config_update_notifier=false

# --- 2. The extension -----------------------------------------------------------------------
say "extension: npm ci && npm run package"
npm_ci "$EXT_DIR"
(cd "$EXT_DIR" && npm run package)

# The Python that builds bt-lsp's wheel and downloads the others: $BT_LSP_PYTHON, else the
# repository's virtual environment (scripts/setup.sh makes it), else python3.
PYTHON=${BT_LSP_PYTHON:-}
if [ -z "$PYTHON" ]; then
  if [ -x "$REPO_DIR/.venv/bin/python" ]; then PYTHON="$REPO_DIR/.venv/bin/python"; else PYTHON=python3; fi
fi
case "$(uname -s)-$(uname -m)" in
  Linux-x86_64) TARGET=linux-x64 ;;
  Linux-aarch64) TARGET=linux-arm64 ;;
  *) TARGET= ;;
esac
if [ -n "$TARGET" ]; then
  say "extension with its server: scripts/vscode_bundle.py --target $TARGET"
  "$PYTHON" "$REPO_DIR/scripts/vscode_bundle.py" --target "$TARGET"
fi

# --- 3. code-server -----------------------------------------------------------------------
if [ -f "$CS_MARKER" ] && [ -x "$CS_DIR/node_modules/.bin/code-server" ]; then
  say "code-server $CODE_SERVER_VERSION: already installed in $CS_DIR"
else
  say "code-server $CODE_SERVER_VERSION -> $CS_DIR"
  rm -rf "$CS_DIR"
  mkdir -p "$CS_DIR"
  cd "$CS_DIR"
  printf '{ "name": "bt-lsp-e2e-code-server", "private": true }\n' > package.json
  # Its own install script would fetch prebuilt binaries from elsewhere: skip it, redo it below.
  npm install --ignore-scripts --no-save "code-server@$CODE_SERVER_VERSION"
  CS_PKG="$CS_DIR/node_modules/code-server"

  # argon2 is loaded at startup even with --auth none; build it from source.
  (cd node_modules/argon2 && ../.bin/node-pre-gyp install --build-from-source)

  # What code-server's postinstall does, with native modules built from source and
  # @vscode/ripgrep's download replaced by Debian's rg.
  cd "$CS_PKG/lib/vscode"
  node -e '
    const fs = require("fs");
    const p = JSON.parse(fs.readFileSync("package.json", "utf8"));
    p.allowScripts = {
      "@parcel/watcher": true, "@vscode/deviceid": true, "@vscode/spdlog": true, "kerberos": true,
      "native-watchdog": true, "node-pty": true, "@vscode/windows-process-tree": true,
      "@vscode/windows-registry": true, "@vscode/ripgrep": false, "@vscode/windows-ca-certs": false,
    };
    fs.writeFileSync("package.json", JSON.stringify(p, null, 2));'
  npm install --omit=dev
  mkdir -p node_modules/@vscode/ripgrep/bin
  ln -sf "$(command -v rg)" node_modules/@vscode/ripgrep/bin/rg
  ln -sfn node_modules node_modules.asar
  ln -sfn code-linux.sh bin/remote-cli/code-server
  ln -sfn browser-linux.sh bin/helpers/browser.sh
  (cd extensions && npm install --omit=dev --ignore-scripts)

  # (code-server writes a default config and data folders under XDG_* even for --version.)
  scratch=$(mktemp -d)
  XDG_CONFIG_HOME="$scratch" XDG_DATA_HOME="$scratch" "$CS_DIR/node_modules/.bin/code-server" --version
  rm -rf "$scratch"
  touch "$CS_MARKER"
fi

# --- 4. playwright-core -----------------------------------------------------------------------
say "playwright-core: npm ci in $E2E_DIR"
npm_ci "$E2E_DIR"

say "done: extension $EXT_DIR/bt-lsp.vsix, code-server $CS_DIR/node_modules/.bin/code-server, browser $(command -v chromium)"
