#!/usr/bin/env bash
# Installs what `appell view` is built from, and what tests it (idempotent):
#   three.js and esbuild from the npm registry, pinned by viewer/package-lock.json,
#   into viewer/node_modules (`npm ci`); the build bundles them into the command;
#   with --browser: Debian's chromium, for the headless screenshot test.
# Node.js and npm come from Debian when the machine has none.
set -euo pipefail
cd "$(dirname "$0")/.."

apt_install() { bash scripts/apt-install.sh install-viewer-deps "$@"; }

if ! command -v npm >/dev/null || ! command -v node >/dev/null; then apt_install nodejs npm; fi

# npm ci again only when the lock file changed since the last install.
stamp=viewer/node_modules/.appell-lock
if ! cmp -s viewer/package-lock.json "$stamp" 2>/dev/null; then
  echo "install-viewer-deps: npm ci in viewer/ (three.js, esbuild)"
  (cd viewer && npm ci --no-audit --no-fund --loglevel=error)
  cp viewer/package-lock.json "$stamp"
fi

if [ "${1:-}" = "--browser" ] && ! command -v chromium >/dev/null; then apt_install chromium; fi
echo "install-viewer-deps: done"
