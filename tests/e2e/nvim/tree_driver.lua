-- Drives :BtLspTree in a headless Neovim started with tests/e2e/nvim/minimal_init.lua on a
-- BehaviorTree file. Prints each result as "BTLSP-E2E " .. json; ends with `qa!`, or
-- `cquit 1` after printing {"event": "error"}.
--
-- BT_LSP_E2E_LINE: the 1-based line to put the cursor on for `:BtLspTree ports` (which opens
-- the file with the viewer; the test puts a fake xdg-open on PATH); then the cursor goes to
-- line 1 column 1 for `:BtLspTree!` (which only prints the path).

local e2e = dofile(debug.getinfo(1, "S").source:sub(2):match("^(.*)[/\\]") .. "/common.lua")
local emit, wait = e2e.emit, e2e.wait

local function run_tree(command)
  local bt = require("bt_lsp")
  bt.last_tree = nil
  vim.cmd(command)
  wait("the SVG of " .. command, function()
    return bt.last_tree ~= nil
  end)
  return bt.last_tree
end

e2e.run(function()
  local bufnr = vim.api.nvim_get_current_buf()
  local v = vim.version()
  emit("start", { nvim = ("%d.%d.%d"):format(v.major, v.minor, v.patch), mode = require("bt_lsp").mode() })
  wait("a bt_lsp client on the buffer", function()
    for _, client in ipairs(require("bt_lsp").clients()) do
      if vim.lsp.buf_is_attached(bufnr, client.id) and client.initialized ~= false then
        return true
      end
    end
    return false
  end)
  vim.api.nvim_win_set_cursor(0, { tonumber(os.getenv("BT_LSP_E2E_LINE")), 6 })
  local opened = run_tree("BtLspTree ports")
  emit("opened", { path = opened, messages = e2e.messages() })
  vim.api.nvim_win_set_cursor(0, { 1, 0 })
  local printed = run_tree("BtLspTree!")
  emit("printed", { path = printed, messages = e2e.messages() })
  emit("done", {})
end)
