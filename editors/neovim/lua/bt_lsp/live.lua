-- bt-lsp for Neovim: the running tree's node statuses on the buffer (:BtLspMonitor).
--
-- The server watches a BehaviorTree.CPP executor's Groot2 publisher (bt-lsp.liveConnect; it
-- only connects to the host:port given, never listens) and sends bt-lsp/liveStatus
-- notifications: each node's range (the start tag's name) and status. Each node gets an
-- extmark in the namespace "bt_lsp_live": its name highlighted with BtLspLive<Status> and
-- " ● <status>" at the end of its line. See editors/neovim/README.md and docs/live.md.

local M = {}

local api = vim.api

M.namespace = api.nvim_create_namespace("bt_lsp_live")
M.CONNECT = "bt-lsp.liveConnect"
M.DISCONNECT = "bt-lsp.liveDisconnect"
M.NOTIFICATION = "bt-lsp/liveStatus"

-- The highlight group of each status, and the group it is linked to by default.
M.groups = {
  running = "BtLspLiveRunning",
  success = "BtLspLiveSuccess",
  failure = "BtLspLiveFailure",
  idle = "BtLspLiveIdle",
  skipped = "BtLspLiveSkipped",
}
local LINKS = {
  BtLspLiveRunning = "DiagnosticWarn",
  BtLspLiveSuccess = "DiagnosticOk", -- String where there is no DiagnosticOk (before 0.9)
  BtLspLiveFailure = "DiagnosticError",
  BtLspLiveIdle = "Comment",
  BtLspLiveSkipped = "Comment",
}

-- session: the newest session seen; client_id: the client it runs on; marked: buffers with
-- marks; message: the last message shown; last: the last notification.
local state = { session = nil, client_id = nil, marked = {}, message = nil, last = nil }

--- Links the BtLspLive* groups (a colorscheme's own definitions are kept: `default`).
function M.define_highlights()
  for group, target in pairs(LINKS) do
    if target == "DiagnosticOk" and vim.fn.hlexists("DiagnosticOk") == 0 then
      target = "String"
    end
    vim.cmd(("highlight default link %s %s"):format(group, target))
  end
end

--- `host:port`, `[v6]:port`, `host`, `:port` or `port` (defaults 127.0.0.1 and 1667);
--- nil and a reason when it is none of these.
function M.parse_address(text)
  local host, port = "127.0.0.1", 1667
  text = vim.trim(text or "")
  if text == "" then
    return host, port
  end
  local h, p = text:match("^%[(.+)%]:(%d+)$")
  if h == nil then
    h, p = text:match("^([^:]*):(%d+)$")
  end
  if h == nil and text:match("^%d+$") then
    h, p = "", text
  end
  if h == nil then
    if text:find("[%s/@?#]") or (text:find(":", 1, true) and not text:match("^%[.+%]$")) then
      return nil, "not host:port: " .. text
    end
    h = text:gsub("^%[(.*)%]$", "%1")
  end
  port = tonumber(p or port)
  if port == nil or port < 1 or port > 65534 then
    return nil, "the port must be in 1..65534"
  end
  return (h ~= "" and h or host), port
end

-- A loaded buffer whose URI is `uri`, or nil.
local function buffer_of(uri)
  for _, bufnr in ipairs(api.nvim_list_bufs()) do
    if api.nvim_buf_is_loaded(bufnr) and vim.uri_from_bufnr(bufnr) == uri then
      return bufnr
    end
  end
  return nil
end

-- The byte column of LSP `character` on `line` in the client's position encoding.
local function byte_col(line, character, encoding)
  if encoding == "utf-8" then
    return math.min(character, #line)
  end
  local ok, col
  if vim.fn.has("nvim-0.11") == 1 then
    ok, col = pcall(vim.str_byteindex, line, encoding, character, false)
  else
    ok, col = pcall(vim.str_byteindex, line, character, encoding == "utf-16")
  end
  return ok and col or #line
end

--- Removes every mark of the live view.
function M.clear()
  for bufnr in pairs(state.marked) do
    if api.nvim_buf_is_valid(bufnr) then
      api.nvim_buf_clear_namespace(bufnr, M.namespace, 0, -1)
    end
  end
  state.marked = {}
end

local function encoding_of(client_id)
  local client = client_id and vim.lsp.get_client_by_id(client_id)
  return client and client.offset_encoding or "utf-16"
end

-- Marks the nodes of one notification (the marks of the previous one removed).
local function draw(result, client_id)
  M.clear()
  if not result.connected or type(result.nodes) ~= "table" then
    return
  end
  local encoding = encoding_of(client_id)
  local lines = {}
  for _, node in ipairs(result.nodes) do
    local bufnr = type(node.uri) == "string" and buffer_of(node.uri) or nil
    local group = M.groups[node.status]
    local r = node.range
    if bufnr ~= nil and group ~= nil and type(r) == "table" and r.start and r["end"] then
      lines[bufnr] = lines[bufnr] or api.nvim_buf_get_lines(bufnr, 0, -1, false)
      local row, end_row = r.start.line, r["end"].line
      local text, end_text = lines[bufnr][row + 1], lines[bufnr][end_row + 1]
      if text ~= nil and end_text ~= nil then
        local col = byte_col(text, r.start.character, encoding)
        local end_col = byte_col(end_text, r["end"].character, encoding)
        pcall(api.nvim_buf_set_extmark, bufnr, M.namespace, row, col, {
          end_row = end_row,
          end_col = end_col,
          hl_group = group,
          virt_text = { { " ● " .. node.status, group } },
          virt_text_pos = "eol",
          priority = 150,
        })
        state.marked[bufnr] = true
      end
    end
  end
end

--- The bt-lsp/liveStatus handler (err, result, ctx): draws the statuses, and says what
--- changed (connected, lost, restarted) once.
function M.on_status(_, result, ctx)
  if type(result) ~= "table" or type(result.session) ~= "number" then
    return
  end
  if state.session ~= nil and result.session < state.session then
    return -- an older session's last words
  end
  state.session = result.session
  state.client_id = ctx and ctx.client_id or state.client_id
  state.last = result
  draw(result, state.client_id)
  local message = type(result.message) == "string" and result.message or nil
  if message ~= nil and message ~= state.message then
    local level = result.connected and vim.log.levels.INFO or vim.log.levels.WARN
    vim.notify("bt-lsp live: " .. message, level)
  end
  state.message = message
end

--- The last bt-lsp/liveStatus notification (nil before the first).
function M.last()
  return state.last
end

-- Requests on a client: client:request() from 0.11 on (the dot form is deprecated there).
local function request(client, method, params, handler, bufnr)
  if vim.fn.has("nvim-0.11") == 1 then
    return client:request(method, params, handler, bufnr)
  end
  return client.request(method, params, handler, bufnr)
end

--- Watches the executor at `address` ("host:port", default 127.0.0.1:1667) on the
--- current buffer, through `client` (a bt-lsp client attached to it). `on_done(result,
--- error message)` is called with the server's answer.
function M.start(client, bufnr, address, on_done)
  on_done = on_done or function() end
  local host, port = M.parse_address(address)
  if host == nil then
    vim.notify("bt-lsp: " .. port, vim.log.levels.ERROR)
    return on_done(nil, port)
  end
  M.define_highlights()
  local params = {
    command = M.CONNECT,
    arguments = { { uri = vim.uri_from_bufnr(bufnr), host = host, port = port } },
  }
  state.client_id = client.id
  request(client, "workspace/executeCommand", params, function(err, result)
    if err then
      local message = "cannot watch " .. host .. ":" .. port .. ": " .. (err.message or vim.inspect(err))
      vim.notify("bt-lsp: " .. message, vim.log.levels.ERROR)
      return on_done(nil, message)
    end
    if type(result) == "table" and type(result.session) == "number" then
      if state.session == nil or result.session > state.session then
        state.session = result.session
      end
      local mismatches = type(result.mismatches) == "table" and #result.mismatches or 0
      local text = ("bt-lsp: watching tree %s at %s:%d (%d nodes mapped"):format(
        tostring(result.tree), host, port, tonumber(result.nodes) or 0)
      if mismatches > 0 then
        text = text .. (", %d differences from the text"):format(mismatches)
      end
      vim.notify(text .. ")", vim.log.levels.INFO)
    end
    on_done(result, nil)
  end, bufnr)
end

--- Stops watching (the server's final notification clears the marks; they are cleared
--- here too, in case the server is gone).
function M.stop(client, on_done)
  on_done = on_done or function() end
  M.clear()
  if client == nil then
    return on_done(nil)
  end
  request(client, "workspace/executeCommand", { command = M.DISCONNECT, arguments = {} }, function(err)
    M.clear()
    on_done(err)
  end)
end

--- Forgets the session when its client stops (its marks removed).
function M.client_stopped(client_id)
  if state.client_id == client_id then
    M.clear()
    state.client_id = nil
    state.last = nil
  end
end

return M
