-- :checkhealth bt_lsp

local M = {}

local function reporter()
  local h = vim.health
  if h ~= nil and h.start ~= nil then -- 0.10+
    return h.start, h.ok, h.warn, h.error, h.info
  end
  h = (h ~= nil and h.report_start ~= nil) and h or require("health") -- 0.8-0.9 / 0.7
  return h.report_start, h.report_ok, h.report_warn, h.report_error, h.report_info
end

local function lsp_message(body)
  local json = vim.json.encode(body)
  return ("Content-Length: %d\r\n\r\n%s"):format(#json, json)
end

-- Runs the server command, sends initialize/shutdown/exit, and returns the initialize
-- result (a table) or nil and an error text.
local function probe(cmd, timeout_ms)
  local output = {}
  local stderr = {}
  local exited = nil
  local ok, job = pcall(vim.fn.jobstart, cmd, {
    on_stdout = function(_, data)
      table.insert(output, table.concat(data, "\n"))
    end,
    on_stderr = function(_, data)
      table.insert(stderr, table.concat(data, "\n"))
    end,
    on_exit = function(_, code)
      exited = code
    end,
  })
  if not ok or job <= 0 then
    return nil, "could not start " .. table.concat(cmd, " ") .. (ok and "" or (": " .. tostring(job)))
  end
  local root = (vim.uv or vim.loop).cwd()
  vim.fn.chansend(job, lsp_message({
    jsonrpc = "2.0",
    id = 1,
    method = "initialize",
    params = {
      processId = vim.NIL,
      rootUri = vim.uri_from_fname(root),
      capabilities = vim.empty_dict(),
    },
  }))
  local result = nil
  local function read_result()
    local text = table.concat(output)
    local pos = 1
    while true do
      local head_end = text:find("\r\n\r\n", pos, true)
      if head_end == nil then
        return false
      end
      local length = tonumber(text:sub(pos, head_end):match("[Cc]ontent%-[Ll]ength:%s*(%d+)"))
      local body_start = head_end + 4
      if length == nil or #text < body_start + length - 1 then
        return false
      end
      local decoded_ok, msg = pcall(vim.json.decode, text:sub(body_start, body_start + length - 1))
      if decoded_ok and type(msg) == "table" and msg.id == 1 and msg.result ~= nil then
        result = msg.result
        return true
      end
      pos = body_start + length
    end
  end
  vim.wait(timeout_ms, function()
    return read_result() or exited ~= nil
  end, 50)
  if exited == nil then
    vim.fn.chansend(job, lsp_message({ jsonrpc = "2.0", id = 2, method = "shutdown" }))
    vim.fn.chansend(job, lsp_message({ jsonrpc = "2.0", method = "exit" }))
    vim.wait(2000, function()
      return exited ~= nil
    end, 50)
    if exited == nil then
      vim.fn.jobstop(job)
    end
  end
  if result == nil then
    local err = vim.trim(table.concat(stderr))
    if err == "" then
      err = exited ~= nil and ("exited with code " .. exited) or "no answer to initialize"
    end
    return nil, err
  end
  return result
end

function M.check()
  local start, ok, warn, error, info = reporter()
  start("bt-lsp")

  local v = vim.version()
  info(("Neovim %d.%d.%d"):format(v.major, v.minor, v.patch))

  local bt = require("bt_lsp")
  local opts = bt.get_opts()
  local mode = bt.mode()
  local how = ({
    config = "vim.lsp.config('bt_lsp') + vim.lsp.enable('bt_lsp')",
    start = "vim.lsp.start() on FileType",
    start_client = "vim.lsp.start_client() on FileType",
  })[mode]
  if opts == nil then
    warn("require('bt_lsp').setup() has not been called", {
      "Add require('bt_lsp').setup() to your config (see editors/neovim/README.md)",
    })
  else
    ok("setup() called; starts the server with " .. how)
    info("filetypes: " .. table.concat(opts.filetypes, ", "))
    info("root markers: " .. table.concat(opts.root_markers, ", "))
  end

  local cmd = opts and opts.cmd or bt.default_cmd()
  local shown = table.concat(cmd, " ")
  if vim.fn.executable(cmd[1]) ~= 1 then
    error(("server command not found: %s"):format(cmd[1]), {
      "Install the server: pip install bt-lsp (puts `bt-lsp` on PATH)",
      "or pass cmd = { '/path/to/python', '-m', 'bt_lsp', 'serve' } to setup()",
    })
    return
  end
  local result, err = probe(cmd, 10000)
  if result == nil then
    error(("`%s` does not run as a language server: %s"):format(shown, err), {
      "Run it in a terminal to see the error",
      "With cmd = python -m bt_lsp serve, that Python needs bt-lsp installed",
    })
    return
  end
  local server = result.serverInfo or {}
  ok(("`%s` runs: %s %s"):format(shown, server.name or "server", server.version or ""))

  local clients = bt.clients()
  if #clients == 0 then
    info("no bt-lsp client is running (open a BehaviorTree.CPP XML file)")
  end
  for _, client in ipairs(clients) do
    info(("client %d: root %s"):format(client.id, tostring(client.config.root_dir)))
  end
end

return M
