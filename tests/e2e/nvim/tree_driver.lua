-- Drives :BtLspTree in a headless Neovim started with tests/e2e/nvim/minimal_init.lua on a
-- BehaviorTree file. Prints each result as "BTLSP-E2E " .. json; ends with `qa!`, or
-- `cquit 1` after printing {"event": "error"}.
--
-- BT_LSP_E2E_LINE: the 1-based line to put the cursor on for `:BtLspTree ports` (which opens
-- the file with the viewer; the test puts a fake xdg-open on PATH); then the cursor goes to
-- line 1 column 1 for `:BtLspTree!` (which only prints the path).

local uv = vim.uv or vim.loop
local TIMEOUT = tonumber(os.getenv("BT_LSP_E2E_WAIT_MS") or "") or 10000
local started = uv.hrtime()

local function emit(event, data)
  data = data or {}
  data.event = event
  data.ms = math.floor((uv.hrtime() - started) / 1e6)
  io.stdout:write("BTLSP-E2E " .. vim.fn.json_encode(data) .. "\n")
  io.stdout:flush()
end

local function wait(what, cond)
  if not vim.wait(TIMEOUT, cond, 20) then
    error("timed out waiting for " .. what, 0)
  end
end

local function messages()
  return vim.api.nvim_exec("messages", true)
end

local function run_tree(command)
  local bt = require("bt_lsp")
  bt.last_tree = nil
  vim.cmd(command)
  wait("the SVG of " .. command, function()
    return bt.last_tree ~= nil
  end)
  return bt.last_tree
end

local ok, err = pcall(function()
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
  emit("opened", { path = opened, messages = messages() })
  vim.api.nvim_win_set_cursor(0, { 1, 0 })
  local printed = run_tree("BtLspTree!")
  emit("printed", { path = printed, messages = messages() })
  emit("done", {})
end)
if not ok then
  emit("error", { message = tostring(err) })
  vim.cmd("cquit 1")
else
  vim.cmd("qa!")
end
