-- bt-lsp for Neovim: starts the bt-lsp language server for BehaviorTree.CPP XML buffers.
--
--   require("bt_lsp").setup({ settings = { debounceMs = 100 } })
--
-- Works on Neovim 0.7 (vim.lsp.start_client), 0.8-0.10 (vim.lsp.start) and 0.11+
-- (vim.lsp.config + vim.lsp.enable). See editors/neovim/README.md.

local M = {}

M.name = "bt_lsp"
-- The settings section the server asks for with workspace/configuration.
M.section = "btLsp"

local uv = vim.uv or vim.loop
local api = vim.api
local live = require("bt_lsp.live")

local defaults = {
  cmd = nil, -- nil: M.default_cmd()
  filetypes = { "xml" },
  root_markers = { ".git", "package.xml", "*.btproj" },
  settings = {},
  on_attach = nil,
  capabilities = nil,
}

-- opts: the options setup() was called with (merged with the defaults).
-- clients: root_dir -> client id (Neovim 0.7 only; newer versions reuse clients themselves).
local state = { opts = nil, clients = {} }

-- How the client is started on this Neovim: "config" (0.11+), "start" (0.8-0.10) or
-- "start_client" (0.7).
function M.mode()
  if vim.fn.has("nvim-0.11") == 1 then
    return "config"
  elseif vim.fn.has("nvim-0.8") == 1 then
    return "start"
  end
  return "start_client"
end

--- The server command used when setup() is not given one: `bt-lsp serve` if `bt-lsp` is on
--- PATH, else `python3 -m bt_lsp serve` (or `python` when there is no `python3`).
function M.default_cmd()
  if vim.fn.executable("bt-lsp") == 1 then
    return { "bt-lsp", "serve" }
  end
  local python = "python3"
  if vim.fn.executable(python) ~= 1 and vim.fn.executable("python") == 1 then
    python = "python"
  end
  return { python, "-m", "bt_lsp", "serve" }
end

--- The options in effect (after setup()), or nil.
function M.get_opts()
  return state.opts
end

-- Tag names that only a BehaviorTree.CPP file has at the top.
local BT_PATTERNS = {
  "<root[%s/>]",
  "<root$",
  "<BehaviorTree[%s/>]",
  "<BehaviorTree$",
  "<TreeNodesModel[%s/>]",
  "<TreeNodesModel$",
}

M.detect_lines = 200

--- True when one of the first 200 lines of the buffer has `<root`, `<BehaviorTree` or
--- `<TreeNodesModel`.
function M.looks_like_bt(bufnr)
  bufnr = (bufnr == nil or bufnr == 0) and api.nvim_get_current_buf() or bufnr
  if not api.nvim_buf_is_loaded(bufnr) then
    return false
  end
  for _, line in ipairs(api.nvim_buf_get_lines(bufnr, 0, M.detect_lines, false)) do
    if line:find("<", 1, true) then
      for _, pat in ipairs(BT_PATTERNS) do
        if line:find(pat) then
          return true
        end
      end
    end
  end
  return false
end

local function glob_to_pattern(glob)
  local pat = glob:gsub("[%^%$%(%)%%%.%[%]%+%-]", "%%%0")
  pat = pat:gsub("%*", ".*"):gsub("%?", ".")
  return "^" .. pat .. "$"
end

local function dir_has(dir, marker)
  if marker:find("[*?]") then
    local pat = glob_to_pattern(marker)
    local handle = uv.fs_scandir(dir)
    if not handle then
      return false
    end
    while true do
      local name = uv.fs_scandir_next(handle)
      if name == nil then
        return false
      end
      if name:match(pat) then
        return true
      end
    end
  end
  return uv.fs_stat(dir .. "/" .. marker) ~= nil
end

--- The nearest folder at or above `path`'s folder that holds one of `markers` (plain names
--- or globs like "*.btproj"); the file's own folder when none does.
function M.find_root(path, markers)
  local start = vim.fn.fnamemodify(path, ":p:h")
  local dir = start
  while true do
    for _, marker in ipairs(markers) do
      if dir_has(dir, marker) then
        return dir
      end
    end
    local parent = vim.fn.fnamemodify(dir, ":h")
    if parent == dir then
      return start
    end
    dir = parent
  end
end

-- The file path of a buffer the server can work on, or nil.
local function file_of(bufnr)
  if not api.nvim_buf_is_valid(bufnr) or not api.nvim_buf_is_loaded(bufnr) then
    return nil
  end
  if vim.bo[bufnr].buftype ~= "" then
    return nil
  end
  local name = api.nvim_buf_get_name(bufnr)
  if name == "" or name:match("^%a[%w+.-]*://") then
    return nil -- unnamed, or fugitive://, oil://, ...
  end
  return name
end

local function has_value(list, value)
  for _, v in ipairs(list or {}) do
    if v == value then
      return true
    end
  end
  return false
end

--- The root folder for a buffer if bt-lsp should run on it (a file of one of the configured
--- filetypes that looks like BehaviorTree.CPP XML), else nil.
function M.root_for(bufnr, filetypes)
  local opts = state.opts or defaults
  local path = file_of(bufnr)
  if path == nil then
    return nil
  end
  if not has_value(filetypes or opts.filetypes, vim.bo[bufnr].filetype) then
    return nil
  end
  if not M.looks_like_bt(bufnr) then
    return nil
  end
  return M.find_root(path, opts.root_markers)
end

-- JSON needs {} for objects; Neovim encodes an empty Lua table as [].
local function json_object(value)
  if type(value) ~= "table" then
    return value
  end
  if next(value) == nil then
    return vim.empty_dict()
  end
  local out = {}
  for k, v in pairs(value) do
    out[k] = json_object(v)
  end
  return out
end

-- The client configuration shared by every Neovim version (no root_dir).
local function base_config()
  local opts = state.opts
  local settings = json_object(opts.settings or {})
  local config = {
    name = M.name,
    cmd = opts.cmd,
    init_options = settings,
    settings = { [M.section] = settings },
    on_attach = opts.on_attach,
    on_exit = function(_, _, client_id)
      vim.schedule(function()
        live.client_stopped(client_id)
      end)
    end,
  }
  local capabilities = vim.lsp.protocol.make_client_capabilities()
  -- Neovim 0.7 answers workspace/configuration (from `settings`) but does not say so.
  capabilities.workspace = capabilities.workspace or {}
  if capabilities.workspace.configuration == nil then
    capabilities.workspace.configuration = true
  end
  if opts.capabilities then
    capabilities = vim.tbl_deep_extend("force", capabilities, opts.capabilities)
  end
  config.capabilities = capabilities
  return config
end

--- The bt-lsp clients that are running.
function M.clients()
  if vim.lsp.get_clients then
    return vim.lsp.get_clients({ name = M.name })
  end
  local found = {}
  for _, client in pairs(vim.lsp.get_active_clients()) do
    if client.name == M.name then
      table.insert(found, client)
    end
  end
  return found
end

local function client_stopped(client)
  if client == nil or vim.lsp.get_client_by_id(client.id) == nil then
    return true
  end
  if vim.fn.has("nvim-0.10") == 1 then
    return client:is_stopped()
  end
  return client.is_stopped()
end

-- Neovim 0.7: one client per root, started with vim.lsp.start_client.
local function attach_0_7(bufnr, root)
  local id = state.clients[root]
  if id ~= nil and client_stopped(vim.lsp.get_client_by_id(id)) then
    id = nil
  end
  if id == nil then
    local config = base_config()
    config.root_dir = root
    local stopped = config.on_exit
    config.on_exit = function(code, signal, client_id)
      if state.clients[root] == client_id then
        state.clients[root] = nil
      end
      stopped(code, signal, client_id)
    end
    id = vim.lsp.start_client(config)
    if id == nil then
      return nil
    end
    state.clients[root] = id
  end
  vim.lsp.buf_attach_client(bufnr, id)
  return id
end

--- Starts (or reuses) the client for `bufnr` if it is a BehaviorTree.CPP XML file.
--- Returns the client id, or nil when the buffer is not one bt-lsp handles.
function M.attach(bufnr)
  if state.opts == nil then
    error("bt_lsp: call require('bt_lsp').setup() first")
  end
  bufnr = (bufnr == nil or bufnr == 0) and api.nvim_get_current_buf() or bufnr
  local mode = M.mode()
  local filetypes = nil
  local config
  if mode == "config" then
    config = vim.deepcopy(vim.lsp.config[M.name])
    filetypes = config.filetypes
  end
  local root = M.root_for(bufnr, filetypes)
  if root == nil then
    return nil
  end
  if mode == "start_client" then
    return attach_0_7(bufnr, root)
  end
  config = config or base_config()
  config.root_dir = root
  local id
  api.nvim_buf_call(bufnr, function()
    id = vim.lsp.start(config, { bufnr = bufnr })
  end)
  return id
end

local function attached(bufnr)
  for _, client in ipairs(M.clients()) do
    if vim.lsp.buf_is_attached(bufnr, client.id) then
      return true
    end
  end
  return false
end

local function attach_all()
  for _, bufnr in ipairs(api.nvim_list_bufs()) do
    if api.nvim_buf_is_loaded(bufnr) and not attached(bufnr) then
      M.attach(bufnr)
    end
  end
end

--- Stops every bt-lsp client, then starts them again for the buffers they served.
function M.restart()
  local clients = M.clients()
  local buffers = {}
  for _, client in ipairs(clients) do
    for _, bufnr in ipairs(api.nvim_list_bufs()) do
      if vim.lsp.buf_is_attached(bufnr, client.id) then
        buffers[bufnr] = true
      end
    end
    vim.lsp.stop_client(client.id)
  end
  state.clients = {}
  local function start_again()
    for bufnr in pairs(buffers) do
      if api.nvim_buf_is_valid(bufnr) then
        M.attach(bufnr)
      end
    end
    attach_all()
  end
  local deadline = uv.now() + 5000
  local timer = uv.new_timer()
  timer:start(50, 50, vim.schedule_wrap(function()
    local running = false
    for _, client in ipairs(clients) do
      if not client_stopped(client) then
        running = true
      end
    end
    if running and uv.now() < deadline then
      return
    end
    if running then
      for _, client in ipairs(clients) do
        vim.lsp.stop_client(client.id, true)
      end
    end
    timer:stop()
    timer:close()
    start_again()
  end))
end

-- Requests on a client: client:request() from 0.11 on (the dot form is deprecated there).
local function client_request(client, method, params, handler, bufnr)
  if vim.fn.has("nvim-0.11") == 1 then
    return client:request(method, params, handler, bufnr)
  end
  return client.request(method, params, handler, bufnr)
end

-- The viewer for a file: vim.ui.open() on 0.10+, else xdg-open (or open on macOS), else nil.
local function open_file(path)
  if vim.ui.open then
    local _, err = vim.ui.open(path)
    return err == nil, err
  end
  for _, opener in ipairs({ "xdg-open", "open" }) do
    if vim.fn.executable(opener) == 1 then
      local job = vim.fn.jobstart({ opener, path }, { detach = true })
      return job > 0, job > 0 and nil or ("could not run " .. opener)
    end
  end
  return false, "no viewer found (xdg-open)"
end

--- Where :BtLspTree writes the picture of `tree` of buffer `bufnr`: `<file>-<tree>.svg` in
--- stdpath("cache")/bt_lsp/trees (kept after Neovim exits, for the viewer; rewritten each time).
function M.tree_path(tree, bufnr)
  local function safe(text)
    local out = tostring(text):gsub("[^%w_.-]", "_")
    return out ~= "" and out or "tree"
  end
  local dir = vim.fn.stdpath("cache") .. "/bt_lsp/trees"
  vim.fn.mkdir(dir, "p")
  local stem = vim.fn.fnamemodify(api.nvim_buf_get_name(bufnr or 0), ":t:r")
  return ("%s/%s-%s.svg"):format(dir, safe(stem), safe(tree))
end

-- The bt-lsp client attached to `bufnr`, or nil.
local function buffer_client(bufnr)
  local found = nil
  for _, c in ipairs(M.clients()) do
    if vim.lsp.buf_is_attached(bufnr, c.id) then
      found = c
    end
  end
  return found
end

--- Shows the statuses of a running tree on the current buffer (:BtLspMonitor): the server
--- connects to the executor's Groot2 publisher at `address` ("host:port", default
--- 127.0.0.1:1667) and each node gets a highlight and " ● <status>" (bt_lsp.live).
--- `on_done(result, error message)` is called with the server's answer.
function M.monitor(address, on_done)
  local bufnr = api.nvim_get_current_buf()
  local client = buffer_client(bufnr)
  if client == nil then
    local message = "no bt-lsp server is running for this buffer"
    vim.notify("bt-lsp: " .. message, vim.log.levels.ERROR)
    if on_done then
      on_done(nil, message)
    end
    return
  end
  live.start(client, bufnr, address, on_done)
end

--- Stops :BtLspMonitor (the marks are removed).
function M.monitor_stop(on_done)
  local client = buffer_client(api.nvim_get_current_buf()) or M.clients()[1]
  live.stop(client, on_done)
end

--- Renders the behavior tree under the cursor to an SVG file (the server's bt-lsp.renderTree
--- command) and opens it with the system viewer, or only prints its path. Options:
---   ports            show each node's ports
---   expand_subtrees  draw called trees below their SubTree nodes
---   open             open the file (default true); the path is printed either way
---   path             where to write (default: M.tree_path(tree ID, buffer))
---   on_done          function(path or nil, error message or nil), called when done
function M.tree(opts)
  opts = opts or {}
  local bufnr = api.nvim_get_current_buf()
  local done = opts.on_done or function() end
  local client = buffer_client(bufnr)
  local function fail(message)
    vim.notify("bt-lsp: " .. message, vim.log.levels.ERROR)
    done(nil, message)
  end
  if client == nil then
    return fail("no bt-lsp server is running for this buffer")
  end
  local position = vim.lsp.util.make_position_params(0, client.offset_encoding).position
  local params = {
    command = "bt-lsp.renderTree",
    arguments = {
      {
        uri = vim.uri_from_bufnr(bufnr),
        position = position,
        format = "svg",
        ports = opts.ports == true,
        expandSubtrees = opts.expand_subtrees == true,
      },
    },
  }
  client_request(client, "workspace/executeCommand", params, function(err, result)
    if err then
      return fail("drawing the tree: " .. (err.message or vim.inspect(err)))
    end
    if result == nil or result == vim.NIL then
      return fail("no <BehaviorTree> in this buffer")
    end
    local path = opts.path or M.tree_path(result.tree, bufnr)
    local file, why = io.open(path, "wb")
    if file == nil then
      return fail("cannot write " .. path .. ": " .. tostring(why))
    end
    file:write(result.svg)
    file:close()
    M.last_tree = path
    local message = ("bt-lsp: tree '%s' written to %s"):format(result.tree, path)
    if opts.open ~= false then
      local ok, open_err = open_file(path)
      if not ok then
        message = message .. " (not opened: " .. tostring(open_err) .. ")"
      end
    end
    vim.notify(message, vim.log.levels.INFO)
    done(path, nil)
  end, bufnr)
end

local function create_commands()
  api.nvim_create_user_command("BtLspMonitor", function(args)
    M.monitor(args.args)
  end, {
    nargs = "?",
    desc = "Show a running tree's node statuses on this buffer (host:port, default 127.0.0.1:1667)",
  })
  api.nvim_create_user_command("BtLspMonitorStop", function()
    M.monitor_stop()
  end, { desc = "Stop showing the running tree's node statuses" })
  api.nvim_create_user_command("BtLspRestart", function()
    M.restart()
  end, { desc = "Restart the bt-lsp language server" })
  api.nvim_create_user_command("BtLspTree", function(args)
    local words = {}
    for _, w in ipairs(args.fargs) do
      words[w] = true
    end
    M.tree({ ports = words.ports, expand_subtrees = words.expand, open = not args.bang })
  end, {
    nargs = "*",
    bang = true,
    complete = function()
      return { "ports", "expand" }
    end,
    desc = "Draw the behavior tree under the cursor as SVG and open it (! only prints its path)",
  })
end

local function check(name, value, kind, optional)
  if (value == nil and optional) or type(value) == kind then
    return
  end
  error(("bt_lsp.setup: %s must be a %s, not %s"):format(name, kind, type(value)), 3)
end

--- Sets bt-lsp up. Options (all optional):
---   cmd           argv of the server (default: M.default_cmd())
---   filetypes     filetypes to look at (default {"xml"}); only buffers whose first 200
---                 lines contain <root, <BehaviorTree or <TreeNodesModel get a client
---   root_markers  files or globs marking the project root (default {".git", "package.xml",
---                 "*.btproj"}); one client runs per root
---   settings      the btLsp settings (debounceMs, severity, maxDocumentBytes, rosPackages,
---                 modelFiles), sent as initializationOptions and for workspace/configuration
---   on_attach     function(client, bufnr)
---   capabilities  merged into vim.lsp.protocol.make_client_capabilities()
function M.setup(opts)
  opts = vim.tbl_extend("force", vim.deepcopy(defaults), opts or {})
  if opts.cmd == nil then
    opts.cmd = M.default_cmd()
  end
  if type(opts.cmd) == "string" then
    opts.cmd = { opts.cmd }
  end
  check("cmd", opts.cmd, "table")
  check("filetypes", opts.filetypes, "table")
  check("root_markers", opts.root_markers, "table")
  check("settings", opts.settings, "table")
  check("on_attach", opts.on_attach, "function", true)
  check("capabilities", opts.capabilities, "table", true)
  if #opts.cmd == 0 then
    error("bt_lsp.setup: cmd is empty", 2)
  end
  state.opts = opts

  local group = api.nvim_create_augroup("bt_lsp", { clear = true })
  local mode = M.mode()

  if mode == "config" then
    local config = base_config()
    config.filetypes = opts.filetypes
    config.root_dir = function(bufnr, on_dir)
      local root = M.root_for(bufnr, vim.lsp.config[M.name].filetypes)
      if root ~= nil then
        on_dir(root)
      end
    end
    vim.lsp.config(M.name, config)
    vim.lsp.enable(M.name)
  else
    api.nvim_create_autocmd("FileType", {
      group = group,
      pattern = opts.filetypes,
      callback = function(args)
        M.attach(args.buf)
      end,
      desc = "bt-lsp: start the server for BehaviorTree.CPP XML",
    })
    attach_all()
  end

  -- A new file only looks like BehaviorTree.CPP XML once it has some text: look again
  -- when it is written.
  api.nvim_create_autocmd("BufWritePost", {
    group = group,
    callback = function(args)
      if not attached(args.buf) then
        M.attach(args.buf)
      end
    end,
    desc = "bt-lsp: start the server once a file looks like BehaviorTree.CPP XML",
  })

  -- The statuses of a running tree (:BtLspMonitor), for every bt-lsp client.
  vim.lsp.handlers[live.NOTIFICATION] = live.on_status
  live.define_highlights()
  api.nvim_create_autocmd("ColorScheme", {
    group = group,
    callback = live.define_highlights,
    desc = "bt-lsp: link the live status highlight groups again",
  })

  create_commands()
  return M
end

return M
