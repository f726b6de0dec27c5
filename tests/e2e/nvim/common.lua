-- What the Neovim drivers (driver.lua, tree_driver.lua) share: results printed to stdout as
-- "BTLSP-E2E " .. json lines, waiting with a timeout, :messages, and the run that ends with
-- `qa!`, or with `cquit 1` after printing {"event": "error"} on any failure.
-- Loaded with dofile() from beside the driver: `local e2e = dofile(<dir> .. "/common.lua")`.

local M = {}

local uv = vim.uv or vim.loop
local started = uv.hrtime()

M.TIMEOUT = tonumber(os.getenv("BT_LSP_E2E_WAIT_MS") or "") or 10000

function M.emit(event, data)
  data = data or {}
  data.event = event
  data.ms = math.floor((uv.hrtime() - started) / 1e6)
  io.stdout:write("BTLSP-E2E " .. vim.fn.json_encode(data) .. "\n")
  io.stdout:flush()
end

function M.wait(what, cond, ms)
  if not vim.wait(ms or M.TIMEOUT, cond, 20) then
    error("timed out waiting for " .. what, 0)
  end
end

-- What Neovim showed in :messages (warnings such as deprecations end up there).
function M.messages()
  return vim.api.nvim_exec2 and vim.api.nvim_exec2("messages", { output = true }).output
    or vim.api.nvim_exec("messages", true)
end

function M.run(main)
  local ok, err = xpcall(main, debug.traceback)
  if not ok then
    M.emit("error", { message = tostring(err) })
    vim.cmd("cquit 1")
  end
  vim.cmd("qa!")
end

return M
