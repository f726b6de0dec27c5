-- bt-lsp, the language server for BehaviorTree.CPP XML, as a Neovim 0.11+ LSP configuration:
-- the table `vim.lsp.config()` reads from an `lsp/` folder of the runtimepath (and the form
-- nvim-lspconfig's `lsp/*.lua` configurations have). With this folder's parent
-- (editors/neovim) on the runtimepath, or the file copied to ~/.config/nvim/lsp/:
--
--   vim.lsp.enable("bt_lsp")
--   vim.lsp.config("bt_lsp", { settings = { btLsp = { debounceMs = 100 } } })  -- optional
--
-- The server gives no diagnostics for XML that is not BehaviorTree.CPP's (package.xml,
-- launch files), so attaching it to every xml buffer is harmless. The plugin
-- (require("bt_lsp").setup()) is the alternative that starts it only for BehaviorTree.CPP
-- files and also works on Neovim 0.7-0.10. Settings: https://bt-lsp.github.io/bt-lsp/configuration/
return {
  cmd = { "bt-lsp", "serve" },
  filetypes = { "xml" },
  -- The nearest folder holding one of these is the root (one server per root).
  root_markers = { "bt-lsp.toml", "package.xml", ".git" },
  -- The btLsp section the server asks for with workspace/configuration.
  settings = {
    btLsp = vim.empty_dict(),
  },
}
