-- Drives a headless Neovim that was started with tests/e2e/nvim/minimal_init.lua on one file.
-- Each result is printed to stdout as one line: "BTLSP-E2E " .. json. Ends with `qa!`, or
-- `cquit 1` after printing {"event": "error"} on any failure.
--
-- BT_LSP_E2E_SCENARIO:
--   "quickfix"  (default) the file is the BehaviorTree fixture: diagnostics, hover on
--               'Main Tree', the preferred quick fix through vim.lsp.buf.code_action(),
--               the buffer after it, the diagnostics the server publishes again.
--   "hover"     the file is a BehaviorTree file: the hover on BT_LSP_E2E_HOVER_NEEDLE in the
--               first line containing BT_LSP_E2E_HOVER_CONTEXT, as the server sent it, as
--               the float's buffer holds it and as the float shows it (conceal applied).
--   "no-client" the file is plain XML: no client may start for it; then BT_LSP_E2E_OTHER
--               (a BehaviorTree file) is opened to show that the plugin was working.

local e2e = dofile(debug.getinfo(1, "S").source:sub(2):match("^(.*)[/\\]") .. "/common.lua")
local emit, wait, TIMEOUT = e2e.emit, e2e.wait, e2e.TIMEOUT
local uv = vim.uv or vim.loop

local function buf_clients(bufnr)
  local found = {}
  if vim.lsp.get_clients then
    found = vim.lsp.get_clients({ bufnr = bufnr })
  else
    for _, client in pairs(vim.lsp.buf_get_clients(bufnr)) do
      table.insert(found, client)
    end
  end
  return found
end

local function all_clients()
  return vim.lsp.get_clients and vim.lsp.get_clients() or vim.lsp.get_active_clients()
end

local function client_info(client)
  return {
    id = client.id,
    name = client.name,
    root_dir = client.config.root_dir,
    offset_encoding = client.offset_encoding,
  }
end

local function diagnostics(bufnr)
  local out = {}
  for _, d in ipairs(vim.diagnostic.get(bufnr)) do
    local code = d.code
    if code == nil and d.user_data and d.user_data.lsp then
      code = d.user_data.lsp.code
    end
    table.insert(out, {
      lnum = d.lnum,
      col = d.col,
      end_lnum = d.end_lnum,
      end_col = d.end_col,
      severity = d.severity,
      code = code or vim.NIL,
      source = d.source or vim.NIL,
      message = d.message,
    })
  end
  table.sort(out, function(a, b)
    if a.lnum ~= b.lnum then
      return a.lnum < b.lnum
    end
    if a.col ~= b.col then
      return a.col < b.col
    end
    return tostring(a.code) < tostring(b.code)
  end)
  return out
end

local function version()
  local v = vim.version()
  return ("%d.%d.%d"):format(v.major, v.minor, v.patch)
end

-- 0-based row and byte column of `needle` in the first line containing `context`.
local function locate(bufnr, context, needle)
  for i, line in ipairs(vim.api.nvim_buf_get_lines(bufnr, 0, -1, false)) do
    local at = line:find(context, 1, true)
    if at then
      return i - 1, line:find(needle, at, true) - 1
    end
  end
  error("not in the buffer: " .. context, 0)
end

local function wait_attached(bufnr)
  wait("a bt_lsp client on the buffer", function()
    for _, client in ipairs(buf_clients(bufnr)) do
      if client.name == "bt_lsp" and client.initialized ~= false then
        return true
      end
    end
    return false
  end)
  for _, client in ipairs(buf_clients(bufnr)) do
    if client.name == "bt_lsp" then
      return client
    end
  end
end

-- Diagnostics that stopped changing for `quiet_ms`.
local function settled_diagnostics(bufnr, quiet_ms, differs_from)
  wait("diagnostics", function()
    local now = vim.fn.json_encode(diagnostics(bufnr))
    return #vim.diagnostic.get(bufnr) > 0 and now ~= differs_from
  end)
  local last = vim.fn.json_encode(diagnostics(bufnr))
  local stable_since = uv.now()
  vim.wait(quiet_ms * 4, function()
    local now = vim.fn.json_encode(diagnostics(bufnr))
    if now ~= last then
      last, stable_since = now, uv.now()
    end
    return uv.now() - stable_since >= quiet_ms
  end, 20)
  return diagnostics(bufnr)
end

-- The LSP character offset of byte column `col` in row `row`, in the client's encoding.
local function character(bufnr, client, row, col)
  local line = vim.api.nvim_buf_get_lines(bufnr, row, row + 1, true)[1]
  local enc = client.offset_encoding
  if enc == "utf-8" then
    return col
  end
  if vim.fn.has("nvim-0.11") == 1 then
    return vim.str_utfindex(line, enc, col)
  end
  local utf32, utf16 = vim.str_utfindex(line, col)
  return enc == "utf-16" and utf16 or utf32
end

local function hover(bufnr, client, row, col)
  -- The raw Markdown, as the server sent it.
  local params = {
    textDocument = { uri = vim.uri_from_bufnr(bufnr) },
    position = { line = row, character = character(bufnr, client, row, col) },
  }
  local responses = vim.lsp.buf_request_sync(bufnr, "textDocument/hover", params, TIMEOUT)
  local markdown = nil
  for _, r in pairs(responses or {}) do
    if r.err then
      error("hover failed: " .. vim.inspect(r.err), 0)
    end
    if r.result and r.result.contents then
      markdown = r.result.contents.value or r.result.contents
    end
  end
  -- What the user sees: vim.lsp.buf.hover() with the cursor there opens a float.
  vim.api.nvim_win_set_cursor(0, { row + 1, col })
  local before = {}
  for _, w in ipairs(vim.api.nvim_list_wins()) do
    before[w] = true
  end
  vim.lsp.buf.hover()
  local float = nil
  wait("the hover window", function()
    for _, w in ipairs(vim.api.nvim_list_wins()) do
      if not before[w] and vim.api.nvim_win_get_config(w).relative ~= "" then
        float = w
        return true
      end
    end
    return false
  end)
  local shown = vim.api.nvim_buf_get_lines(vim.api.nvim_win_get_buf(float), 0, -1, false)
  local seen = e2e.seen_lines(float)
  vim.api.nvim_win_close(float, true)
  return markdown, shown, seen
end

local function quickfix_scenario()
  local bufnr = vim.api.nvim_get_current_buf()
  emit("start", { nvim = version(), mode = require("bt_lsp").mode(), filetype = vim.bo.filetype })
  local client = wait_attached(bufnr)
  emit("attached", { client = client_info(client) })

  local diags = settled_diagnostics(bufnr, 200)
  emit("diagnostics", { items = diags })

  local row, col = locate(bufnr, '<BehaviorTree ID="Main Tree"', "Main Tree")
  local markdown, shown, seen = hover(bufnr, client, row, col + 2)
  emit("hover", { markdown = markdown or vim.NIL, window = shown, seen = seen })

  -- The quick fix, as a user gets it: cursor on the name, code_action(), pick from the list.
  vim.api.nvim_win_set_cursor(0, { row + 1, col + 2 })
  local offered = nil
  vim.ui.select = function(items, opts, on_choice)
    offered = {}
    local pick = nil
    for i, item in ipairs(items) do
      local action = item.action or item[2]
      local title = opts.format_item and opts.format_item(item) or action.title
      table.insert(offered, {
        title = title,
        kind = action.kind or vim.NIL,
        isPreferred = action.isPreferred == true,
      })
      if pick == nil and vim.startswith(title, "Rename 'Main Tree'") then
        pick = i
      end
    end
    emit("actions", { items = offered, picked = pick or vim.NIL })
    if pick ~= 1 then
      on_choice(nil, nil)
      return
    end
    on_choice(items[pick], pick)
  end
  local tick = vim.api.nvim_buf_get_changedtick(bufnr)
  local before = vim.fn.json_encode(diagnostics(bufnr))
  vim.lsp.buf.code_action()
  wait("the code action list", function()
    return offered ~= nil
  end)
  if offered[1] == nil or not vim.startswith(offered[1].title, "Rename 'Main Tree'") then
    error("the first code action is not the rename of 'Main Tree'", 0)
  end
  if not offered[1].isPreferred then
    error("the rename of 'Main Tree' is not marked preferred", 0)
  end
  wait("the quick fix to change the buffer", function()
    return vim.api.nvim_buf_get_changedtick(bufnr) ~= tick
  end)
  -- Both places may come as separate edits; give the last one a moment.
  vim.wait(200, function()
    return not table.concat(vim.api.nvim_buf_get_lines(bufnr, 0, -1, false), "\n"):find("Main Tree")
  end, 20)
  emit("buffer", {
    lines = vim.api.nvim_buf_get_lines(bufnr, 0, -1, false),
    modified = vim.bo[bufnr].modified,
  })

  emit("diagnostics_after", { items = settled_diagnostics(bufnr, 200, before) })
end

local function hover_scenario()
  local bufnr = vim.api.nvim_get_current_buf()
  emit("start", { nvim = version(), mode = require("bt_lsp").mode(), filetype = vim.bo.filetype })
  local client = wait_attached(bufnr)
  emit("attached", { client = client_info(client) })
  emit("diagnostics", { items = settled_diagnostics(bufnr, 200) })
  local context = os.getenv("BT_LSP_E2E_HOVER_CONTEXT")
  local needle = os.getenv("BT_LSP_E2E_HOVER_NEEDLE")
  local row, col = locate(bufnr, context, needle)
  local markdown, shown, seen = hover(bufnr, client, row, col + 1)
  emit("hover", { markdown = markdown or vim.NIL, window = shown, seen = seen })
end

local function no_client_scenario()
  local bufnr = vim.api.nvim_get_current_buf()
  emit("start", { nvim = version(), mode = require("bt_lsp").mode(), filetype = vim.bo.filetype })
  -- Starting a client is synchronous on FileType (0.7-0.10) or one tick later (0.11); give
  -- it ample time to happen if it were going to.
  vim.wait(1000, function()
    return #all_clients() > 0
  end, 20)
  local info = {}
  for _, client in ipairs(all_clients()) do
    table.insert(info, client_info(client))
  end
  emit("plain", {
    buffer_clients = #buf_clients(bufnr),
    clients = info,
  })

  local other = os.getenv("BT_LSP_E2E_OTHER")
  if other then
    vim.cmd("edit " .. vim.fn.fnameescape(other))
    local bt_buf = vim.api.nvim_get_current_buf()
    local client = wait_attached(bt_buf)
    emit("other", {
      filetype = vim.bo[bt_buf].filetype,
      client = client_info(client),
      plain_buffer_clients = #buf_clients(bufnr),
    })

    -- :BtLspRestart replaces the client with a new one on the same buffer.
    vim.cmd("BtLspRestart")
    local restarted = nil
    wait("a new client after :BtLspRestart", function()
      for _, c in ipairs(buf_clients(bt_buf)) do
        if c.name == "bt_lsp" and c.id ~= client.id and c.initialized ~= false then
          restarted = c
          return true
        end
      end
      return false
    end)
    local running = {}
    for _, c in ipairs(all_clients()) do
      table.insert(running, client_info(c))
    end
    emit("restarted", { client = client_info(restarted), clients = running })
  end
end

local scenarios = {
  quickfix = quickfix_scenario,
  hover = hover_scenario,
  ["no-client"] = no_client_scenario,
}

local function main()
  local name = os.getenv("BT_LSP_E2E_SCENARIO") or "quickfix"
  local run = scenarios[name]
  if run == nil then
    error("unknown BT_LSP_E2E_SCENARIO " .. name, 0)
  end
  run()
  -- Stop the server cleanly so that nothing outlives nvim.
  for _, client in ipairs(all_clients()) do
    vim.lsp.stop_client(client.id)
  end
  vim.wait(3000, function()
    return #all_clients() == 0
  end, 20)
  emit("done", { messages = e2e.messages() })
end

e2e.run(main)
