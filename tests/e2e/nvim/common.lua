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

-- The lines of window `win` as they are drawn: what the conceal of the window's syntax
-- (Neovim 0.7's regex Markdown syntax, synconcealed()) or of its tree-sitter highlighter
-- (0.10+: captures with `conceal` metadata) hides or replaces is left out or replaced, as
-- 'conceallevel' 2 shows it. The buffer's lines alone keep what the user never sees.
function M.seen_lines(win)
  local buf = vim.api.nvim_win_get_buf(win)
  local lines = vim.api.nvim_buf_get_lines(buf, 0, -1, false)
  local level = vim.api.nvim_win_get_option(win, "conceallevel")
  local ts = vim.treesitter.highlighter and vim.treesitter.highlighter.active[buf]
  if ts and level > 0 then
    ts.tree:parse(true) -- what a redraw would parse, injections (inline Markdown) included
  end
  local out = {}
  vim.api.nvim_win_call(win, function()
    for row, line in ipairs(lines) do
      local text, last = {}, nil
      local col = 0
      for i = 0, vim.fn.strchars(line) - 1 do
        local ch = vim.fn.strcharpart(line, i, 1)
        local replaced, region = nil, nil
        if level > 0 then
          local sc = vim.fn.synconcealed(row, col + 1)
          if sc[1] == 1 then
            replaced, region = sc[2], "syntax " .. sc[3]
          end
          if ts then
            for _, cap in ipairs(vim.treesitter.get_captures_at_pos(buf, row - 1, col)) do
              local m = cap.metadata or {}
              local c = m.conceal
              if c == nil and m[cap.id] then
                c = m[cap.id].conceal
              end
              if c ~= nil then
                replaced, region = c, "ts " .. cap.lang .. " " .. cap.id .. " " .. (cap.pattern_id or 0)
              end
            end
          end
        end
        if replaced == nil then
          table.insert(text, ch)
          last = nil
        else
          -- A concealed run shows its replacement once (none when it is "").
          if replaced ~= "" and region ~= last then
            table.insert(text, replaced)
          end
          last = region
        end
        col = col + #ch
      end
      out[row] = table.concat(text)
    end
  end)
  return out
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
