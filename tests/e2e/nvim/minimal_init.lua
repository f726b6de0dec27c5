-- The init a user would have: bt_lsp on the runtimepath, filetype detection on, setup().
-- Used by tests/e2e/test_neovim.py; BT_LSP_E2E_PYTHON is the Python that runs the server.
local this = debug.getinfo(1, "S").source:sub(2)
local repo = vim.fn.fnamemodify(this, ":p:h:h:h:h")
vim.opt.runtimepath:prepend(repo .. "/editors/neovim")
vim.cmd("filetype plugin on")

require("bt_lsp").setup({
  cmd = { os.getenv("BT_LSP_E2E_PYTHON") or "python3", "-m", "bt_lsp", "serve" },
  settings = { debounceMs = 0 },
})
