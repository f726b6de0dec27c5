-- Drives :BtLspMonitor in a headless Neovim started with tests/e2e/nvim/minimal_init.lua on a
-- BehaviorTree file that a BehaviorTree.CPP executor runs (BT_LSP_E2E_ADDRESS: its
-- host:port). Prints each result as "BTLSP-E2E " .. json; ends with `qa!`, or `cquit 1`
-- after printing {"event": "error"}.
--
-- BT_LSP_E2E_LINE: the 1-based line of a node that runs for a while (a Sleep): the driver
-- waits until it is marked running and prints the marks; kills the executor
-- (BT_LSP_E2E_EXECUTOR_PID) and waits until the marks are gone; then runs
-- :BtLspMonitorStop.

local e2e = dofile(debug.getinfo(1, "S").source:sub(2):match("^(.*)[/\\]") .. "/common.lua")
local emit, wait = e2e.emit, e2e.wait

local live = require("bt_lsp.live")

local function marks(bufnr)
  local out = {}
  for _, m in ipairs(vim.api.nvim_buf_get_extmarks(bufnr, live.namespace, 0, -1, { details = true })) do
    local d = m[4] or {}
    local virt = d.virt_text and d.virt_text[1] or {}
    table.insert(out, {
      row = m[2],
      col = m[3],
      end_row = d.end_row,
      end_col = d.end_col,
      hl_group = d.hl_group,
      virt_text = virt[1],
      virt_group = virt[2],
    })
  end
  return out
end

local function link_of(group)
  local text = vim.api.nvim_exec2 and vim.api.nvim_exec2("highlight " .. group, { output = true }).output
    or vim.api.nvim_exec("highlight " .. group, true)
  return text:match("links to (%S+)")
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
  vim.cmd("BtLspMonitor " .. os.getenv("BT_LSP_E2E_ADDRESS"))
  wait("the first bt-lsp/liveStatus", function()
    local last = live.last()
    return last ~= nil and last.connected
  end)
  wait("the answer to bt-lsp.liveConnect", function()
    return e2e.messages():find("bt-lsp: watching tree", 1, true) ~= nil
  end)
  local line = tonumber(os.getenv("BT_LSP_E2E_LINE")) - 1
  local seen = nil
  wait("the Sleep node marked running", function()
    for _, m in ipairs(marks(bufnr)) do
      if m.row == line and m.hl_group == "BtLspLiveRunning" then
        seen = marks(bufnr)
        return true
      end
    end
    return false
  end)
  local links = {}
  for status, group in pairs(live.groups) do
    links[status] = link_of(group)
  end
  emit("marks", { marks = seen, links = links, messages = e2e.messages() })
  -- The executor stops: its marks go, the notification says the connection is lost.
  local uv = vim.uv or vim.loop
  uv.kill(tonumber(os.getenv("BT_LSP_E2E_EXECUTOR_PID")), 9)
  wait("the connection lost", function()
    local last = live.last()
    return last ~= nil and not last.connected
  end)
  wait("no mark left once lost", function()
    return #marks(bufnr) == 0
  end)
  emit("lost", { last = live.last(), messages = e2e.messages() })
  local stopped = false
  require("bt_lsp").monitor_stop(function()
    stopped = true
  end)
  wait("the disconnect", function()
    return stopped
  end)
  wait("no mark left", function()
    return #marks(bufnr) == 0
  end)
  vim.wait(300) -- a notification after the stop would draw again
  emit("stopped", { marks = marks(bufnr), last = live.last() })
  emit("done", {})
end)
