// Packages the extension for one VS Code target without running `vscode:prepublish` again
// (scripts/vscode_bundle.py runs it once, then packages up to five targets).
//
//   node scripts/pack.js '{"target": "linux-x64", "packagePath": "bt-lsp-linux-x64.vsix"}'

'use strict';

const path = require('node:path');
const { pack } = require('@vscode/vsce/out/package');

const REPO_URL = 'https://github.com/bt-lsp/bt-lsp';

async function main() {
  const options = JSON.parse(process.argv[2]);
  const { packagePath, files } = await pack({
    cwd: path.resolve(__dirname, '..'),
    packagePath: options.packagePath,
    target: options.target,
    dependencies: false,
    baseContentUrl: `${REPO_URL}/blob/HEAD/editors/vscode`,
    baseImagesUrl: `${REPO_URL}/raw/HEAD/editors/vscode`,
  });
  process.stdout.write(`${packagePath} (${files.length} files)\n`);
}

main().catch((error) => {
  process.stderr.write(`${error && error.stack ? error.stack : error}\n`);
  process.exit(1);
});
