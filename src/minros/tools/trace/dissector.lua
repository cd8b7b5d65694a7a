-- TCPROS for Wireshark and tshark, message bodies decoded by type.
--
-- Written by `minros trace dissector` (minros @MINROS_VERSION@). Load it with
--     tshark -X lua_script:minros.lua -r run.pcap -V
-- or copy it into Wireshark's personal Lua plugins folder (Help > About > Folders).
--
-- A TCPROS connection starts with a connection header from each side: a 4-byte
-- little-endian length, then fields, each a 4-byte length and "key=value". After the
-- headers come frames: a 4-byte length and the serialized message (a service response
-- starts with one more byte, ok: 1 a response follows, 0 an error text follows).
-- The publisher's header carries the full text of its type (message_definition), so the
-- bodies of every topic in the capture are decoded from the capture itself: nested types,
-- arrays, strings, time. Service headers carry no definition; the types known below were
-- written into this file by `minros trace dissector` (--type, or the trace files given).
--
-- The dissector finds TCPROS connections by their first bytes (a heuristic on TCP, on by
-- default: Analyze > Enabled Protocols > MINROS-TCPROS), so no "Decode As" is needed.
-- Wireshark's own TCPROS dissector reads every body as if it began with a std_msgs/Header.

local proto = Proto("minros", "TCPROS (minros)")

--- what `minros trace dissector` knew: types whose definition a capture may lack
local KNOWN = {
  messages = {}, -- type -> {md5 = ..., definition = full text}
  services = {}, -- type -> {md5 = ..., request = full text, response = full text}
}
-- @KNOWN_TYPES@

local HEADER_KEYS = {"callerid", "topic", "service", "type", "md5sum", "message_definition",
                     "tcp_nodelay", "latching", "persistent", "probe", "error",
                     "request_type", "response_type"}
local MAX_HEADER = 1000000    -- a larger header length is not TCPROS (or not the start)
local MAX_ITEMS = 20000       -- tree items one PDU may add
local ARRAY_SHOWN = 1000      -- elements of one array put in the tree
local SEPARATOR = string.rep("=", 80)

local pf = {
  header = ProtoField.uint32("minros.header.length", "Connection header length", base.DEC),
  header_field = ProtoField.string("minros.header.field", "Header field"),
  length = ProtoField.uint32("minros.length", "Frame length", base.DEC),
  ok = ProtoField.uint8("minros.ok", "ok", base.DEC),
  msgtype = ProtoField.string("minros.msgtype", "Message type"),
  number = ProtoField.uint32("minros.number", "Number on this connection", base.DEC),
  error_text = ProtoField.string("minros.error_text", "Service error"),
  body = ProtoField.bytes("minros.body", "Body"),
  bool = ProtoField.uint8("minros.bool", "bool", base.DEC),
  int8 = ProtoField.int8("minros.int8", "int8", base.DEC),
  uint8 = ProtoField.uint8("minros.uint8", "uint8", base.DEC),
  int16 = ProtoField.int16("minros.int16", "int16", base.DEC),
  uint16 = ProtoField.uint16("minros.uint16", "uint16", base.DEC),
  int32 = ProtoField.int32("minros.int32", "int32", base.DEC),
  uint32 = ProtoField.uint32("minros.uint32", "uint32", base.DEC),
  int64 = ProtoField.int64("minros.int64", "int64", base.DEC),
  uint64 = ProtoField.uint64("minros.uint64", "uint64", base.DEC),
  float32 = ProtoField.float("minros.float32", "float32"),
  float64 = ProtoField.double("minros.float64", "float64"),
  string = ProtoField.string("minros.string", "string"),
  bytes = ProtoField.bytes("minros.bytes", "bytes"),
}
local header_pf = {}
for _, key in ipairs(HEADER_KEYS) do
  header_pf[key] = ProtoField.string("minros." .. key, key)
end

local fields = {}
for _, field in pairs(pf) do fields[#fields + 1] = field end
for _, field in pairs(header_pf) do fields[#fields + 1] = field end
proto.fields = fields

local ex = {
  truncated = ProtoExpert.new("minros.truncated", "The capture holds only part of this frame",
                              expert.group.UNDECODED, expert.severity.NOTE),
  malformed = ProtoExpert.new("minros.malformed", "Malformed TCPROS", expert.group.MALFORMED,
                              expert.severity.ERROR),
  unknown = ProtoExpert.new("minros.unknown_type", "No definition of this type in the capture",
                            expert.group.UNDECODED, expert.severity.NOTE),
  refused = ProtoExpert.new("minros.refused", "The peer refused the connection",
                            expert.group.RESPONSE_CODE, expert.severity.WARN),
}
proto.experts = {ex.truncated, ex.malformed, ex.unknown, ex.refused}

-- ------------------------------------------------------------------------------ values

--- a float as Python prints it: the shortest text that reads back as the same number
local function float_text(v)
  if v ~= v then return "nan" end
  if v == math.huge then return "inf" end
  if v == -math.huge then return "-inf" end
  if v == 0 then return (1 / v < 0) and "-0.0" or "0.0" end
  local digits, exp
  for p = 1, 17 do
    local s = string.format("%." .. (p - 1) .. "e", v)
    if tonumber(s) == v then
      local mantissa, e = s:match("^(-?[%d%.]+)e([-+]%d+)$")
      digits, exp = mantissa:gsub("[-%.]", ""), tonumber(e)
      break
    end
  end
  local sign = v < 0 and "-" or ""
  if exp >= -5 and exp < 16 then
    if exp >= 0 then
      if #digits <= exp + 1 then
        return sign .. digits .. string.rep("0", exp + 1 - #digits) .. ".0"
      end
      return sign .. digits:sub(1, exp + 1) .. "." .. digits:sub(exp + 2)
    end
    return sign .. "0." .. string.rep("0", -exp - 1) .. digits
  end
  local mantissa = digits:sub(1, 1) .. (#digits > 1 and ("." .. digits:sub(2)) or "")
  return string.format("%s%se%s%02d", sign, mantissa, exp < 0 and "-" or "+", math.abs(exp))
end

local function quote(s)
  return '"' .. s:gsub('[%c"\\]', function(c)
    if c == '"' then return '\\"' end
    if c == "\\" then return "\\\\" end
    if c == "\n" then return "\\n" end
    if c == "\t" then return "\\t" end
    return string.format("\\x%02x", c:byte())
  end) .. '"'
end

local function cut(s, n)
  if #s <= n then return s end
  return s:sub(1, n) .. "…"
end

-- builtin type -> {size, read(range) -> text}
local function int_reader(method)
  return function(range) return tostring(range[method](range)) end
end
local BUILTIN = {
  bool = {1, function(r) return r:le_uint() ~= 0 and "True" or "False" end},
  int8 = {1, int_reader("le_int")}, uint8 = {1, int_reader("le_uint")},
  byte = {1, int_reader("le_int")}, char = {1, int_reader("le_uint")},
  int16 = {2, int_reader("le_int")}, uint16 = {2, int_reader("le_uint")},
  int32 = {4, int_reader("le_int")}, uint32 = {4, int_reader("le_uint")},
  int64 = {8, int_reader("le_int64")}, uint64 = {8, int_reader("le_uint64")},
  float32 = {4, function(r) return float_text(r:le_float()) end},
  float64 = {8, function(r) return float_text(r:le_float()) end},
}
local FIELD_OF = {byte = "int8", char = "uint8"}

-- ------------------------------------------------------------------------- definitions

local function trim(s) return (s:gsub("^%s+", ""):gsub("%s+$", "")) end

local function resolve(name, package)
  if BUILTIN[name] or name == "string" or name == "time" or name == "duration" then
    return name
  end
  if name == "Header" then return "std_msgs/Header" end
  if not name:find("/") then return package .. "/" .. name end
  return name
end

--- the fields of one .msg text: {{name, type, array}} (array: nil, -1 variable, or N)
local function parse_msg(text, package)
  local out = {}
  for line in (text .. "\n"):gmatch("([^\n]*)\n") do
    local clean = trim(line:gsub("#.*$", ""))
    if clean ~= "" and not clean:find("=") then
      local ftype, fname = clean:match("^(%S+)%s+(%S+)$")
      if ftype == nil then return nil, "cannot read the line " .. quote(clean) end
      local base, bounds = ftype:match("^([^%[]+)%[(%d*)%]$")
      local array = nil
      if base then
        ftype = base
        array = bounds == "" and -1 or tonumber(bounds)
      end
      out[#out + 1] = {name = fname, type = resolve(ftype, package), array = array}
    end
  end
  return out
end

local function package_of(type_name) return type_name:match("^([^/]*)/") or "" end

local definitions = {}  -- cache: core type .. "\0" .. text -> {types, core} or {error}

--- the types of a message_definition: core type and every MSG: block
local function parse_definition(core, text)
  local key = core .. "\0" .. text
  local found = definitions[key]
  if found then return found end
  local types, short = {}, {}
  local blocks = {}
  local rest = text:gsub("roslib/Header", "std_msgs/Header")
  local sep = "\n" .. SEPARATOR .. "\n"
  while true do
    local at = rest:find(sep, 1, true)
    if not at then blocks[#blocks + 1] = rest break end
    blocks[#blocks + 1] = rest:sub(1, at - 1)
    rest = rest:sub(at + #sep)
  end
  local result = {core = core, types = types}
  for i, block in ipairs(blocks) do
    local name, body = core, block
    if i > 1 then
      name, body = block:match("^MSG:%s*(%S+)%s*\n?(.*)$")
      if name == nil then
        result = {error = "block " .. (i - 1) .. " of the definition lacks its MSG: line"}
        break
      end
    end
    local spec, problem = parse_msg(body, package_of(name))
    if spec == nil then
      result = {error = name .. ": " .. problem}
      break
    end
    types[name] = spec
    short[name:match("[^/]*$")] = short[name:match("[^/]*$")] and false or name
  end
  if result.types then result.short = short end
  definitions[key] = result
  return result
end

local function lookup(def, name)
  local spec = def.types[name]
  if spec then return spec end
  local other = def.short[name:match("[^/]*$")]
  return other and def.types[other] or nil
end

-- ------------------------------------------------------------------------------ bodies

--- an empty range at offset (or at the end of what the capture has)
local function at(tvb, offset)
  return tvb(math.min(offset, tvb:len()), 0)
end

--- n bytes at offset as a Lua string ("" for none)
local function raw(tvb, offset, n)
  if n <= 0 then return "" end
  return tvb:raw(offset, n)
end

--- Decoding state of one body: where it ends in the capture and on the wire.
local Body = {}
Body.__index = Body

local function new_body(tvb, offset, size)
  local captured = math.max(0, math.min(tvb:len(), offset + size) - offset)
  return setmetatable({tvb = tvb, stop = offset + captured, wire_stop = offset + size,
                       items = 0, cut = false, bad = nil}, Body)
end

--- true when n bytes at offset are in the capture; notes why not otherwise
function Body:have(offset, n)
  if offset + n > self.wire_stop then
    self.bad = self.bad or string.format("needs %d bytes at offset %d, the frame has %d",
                                         n, offset, self.wire_stop)
    return false
  end
  if offset + n > self.stop then
    self.cut = true
    return false
  end
  return true
end

--- a tree item for n bytes at offset: the value read from them (little-endian), or value
function Body:item(tree, field, offset, n, text, le, value)
  self.items = self.items + 1
  if tree == nil or self.items > MAX_ITEMS then return nil end
  local range = n > 0 and self.tvb(offset, n) or at(self.tvb, offset)
  local item
  if value ~= nil then
    item = tree:add(field, range, value)
  elseif le then
    item = tree:add_le(field, range)
  else
    item = tree:add(field, range)
  end
  item:set_text(text)
  return item
end

local decode_message

--- one value of type ftype at offset: (new offset or nil, its text, the tree item)
local function decode_value(body, tree, def, ftype, label, offset, depth)
  local builtin = BUILTIN[ftype]
  if builtin then
    local size, read = builtin[1], builtin[2]
    if not body:have(offset, size) then return nil end
    local text = read(body.tvb(offset, size))
    body:item(tree, pf[FIELD_OF[ftype] or ftype], offset, size, label .. ": " .. text, true)
    return offset + size, text
  end
  if ftype == "string" then
    if not body:have(offset, 4) then return nil end
    local n = body.tvb(offset, 4):le_uint()
    if offset + 4 + n > body.wire_stop then
      body.bad = string.format("a string of %d bytes at offset %d passes the frame's end",
                               n, offset)
      return nil
    end
    local shown = math.max(0, math.min(n, body.stop - offset - 4))
    local text = raw(body.tvb, offset + 4, shown)
    local quoted = quote(cut(text, 200)) .. (shown < n and " (cut by the capture)" or "")
    local item = body:item(tree, pf.string, offset, 4 + shown, label .. ": " .. quoted, false,
                           text)
    if shown < n then body.cut = true return nil end
    return offset + 4 + n, quoted, item
  end
  if ftype == "time" or ftype == "duration" then
    if not body:have(offset, 8) then return nil end
    local reader = ftype == "time" and "le_uint" or "le_int"
    local secs = body.tvb(offset, 4)[reader](body.tvb(offset, 4))
    local nsecs = body.tvb(offset + 4, 4)[reader](body.tvb(offset + 4, 4))
    local text = string.format("%d.%09d", secs, nsecs)
    if ftype == "duration" and (secs < 0 or nsecs < 0) then
      text = string.format("secs=%d, nsecs=%d", secs, nsecs)
    end
    local sub = body:item(tree, pf.bytes, offset, 8, label .. ": " .. text)
    if sub then
      local f = ftype == "time" and pf.uint32 or pf.int32
      body:item(sub, f, offset, 4, "secs: " .. secs, true)
      body:item(sub, f, offset + 4, 4, "nsecs: " .. nsecs, true)
    end
    return offset + 8, text
  end
  local spec = lookup(def, ftype)
  if spec == nil then
    body.bad = "the definition lacks the type " .. ftype
    return nil
  end
  local start = offset
  local sub = tree and tree:add(at(body.tvb, offset), label) or nil
  local stop = decode_message(body, sub, def, spec, offset, depth + 1)
  if sub and stop then sub:set_len(stop - start) end
  return stop, nil, sub
end

local function decode_array(body, tree, def, f, offset, depth)
  local count = f.array
  local start = offset
  if count == -1 then
    if not body:have(offset, 4) then return nil end
    count = body.tvb(offset, 4):le_uint()
    offset = offset + 4
  end
  local builtin = BUILTIN[f.type]
  local min_size = builtin and builtin[1] or ((f.type == "string" or f.type == "time"
                                               or f.type == "duration") and 4 or 0)
  if count * min_size > body.wire_stop - offset then
    body.bad = string.format("%s: %d elements cannot fit in the %d bytes left", f.name, count,
                             body.wire_stop - offset)
    return nil
  end
  if builtin and builtin[1] == 1 and (f.type == "uint8" or f.type == "char") then
    local shown = math.max(0, math.min(count, body.stop - offset))
    local hex = shown > 0 and body.tvb(offset, math.min(shown, 32)):bytes():tohex():lower() or ""
    local text = string.format("%s: %d bytes%s%s", f.name, count, count > 0 and ": " or "",
                               hex .. (count > 32 and " …" or ""))
    body:item(tree, pf.bytes, start, offset - start + shown, text)
    if shown < count then body.cut = true return nil end
    return offset + count
  end
  local sub = tree and tree:add(at(body.tvb, start), f.name) or nil
  local texts = {}
  for i = 0, count - 1 do
    local parent = i < ARRAY_SHOWN and sub or nil
    local stop, text = decode_value(body, parent, def, f.type, "[" .. i .. "]", offset, depth)
    if stop == nil then
      if sub then sub:set_len(math.max(0, math.min(offset, body.stop) - start)) end
      return nil
    end
    if text and #texts < 10 then texts[#texts + 1] = text end
    offset = stop
  end
  if sub then
    sub:set_len(offset - start)
    if #texts > 0 or count == 0 then
      sub:set_text(string.format("%s: [%s%s]", f.name, table.concat(texts, ", "),
                                 count > #texts and ", …" or ""))
    else
      sub:set_text(string.format("%s [%d]", f.name, count))
    end
    if count > ARRAY_SHOWN then
      sub:add(at(body.tvb, start),
              string.format("(%d more elements not shown)", count - ARRAY_SHOWN))
    end
  end
  return offset
end

decode_message = function(body, tree, def, spec, offset, depth)
  if depth > 32 then
    body.bad = "types nested more than 32 deep"
    return nil
  end
  for _, f in ipairs(spec) do
    local stop
    if f.array then
      stop = decode_array(body, tree, def, f, offset, depth)
    else
      stop = decode_value(body, tree, def, f.type, f.name, offset, depth)
    end
    if stop == nil then return nil end
    offset = stop
  end
  return offset
end

-- ------------------------------------------------------------------------ connections

local conns = {}

function proto.init()
  conns = {}
  definitions = {}
end

local tcp_stream = Field.new("tcp.stream")

local function endpoint(address, port) return tostring(address) .. ":" .. port end

--- the state of this packet's connection (Wireshark's TCP stream: a port pair used again
--- later is another stream), and which side sent the packet
local function conn_of(pinfo)
  local a = endpoint(pinfo.src, pinfo.src_port)
  local b = endpoint(pinfo.dst, pinfo.dst_port)
  local stream = tcp_stream()
  local key = (stream and tostring(stream.value) or "") .. " "
    .. (a < b and (a .. " " .. b) or (b .. " " .. a))
  local conn = conns[key]
  if conn == nil then
    conn = {sides = {}, client = nil}
    conns[key] = conn
  end
  return conn, a
end

--- "topic", "service" or "probe", from the client's header
local function kind_of(conn)
  local client = conn.client and conn.sides[conn.client]
  if client == nil then return nil end
  local h = client.fields
  if h.topic then return "topic", h.topic end
  if h.service then return (h.probe == "1" and "probe" or "service"), h.service end
  return nil
end

local function server_of(conn)
  for name, side in pairs(conn.sides) do
    if name ~= conn.client then return side end
  end
  return nil
end

--- the definition frames of this direction are decoded with: (type, def) or (nil, why)
local function frame_type(conn, src)
  local kind = kind_of(conn)
  local server = server_of(conn)
  if kind == nil or server == nil then return nil, "the connection headers are not in the capture" end
  local h = server.fields
  if kind == "topic" then
    local client = conn.sides[conn.client].fields
    local tname = h.type or client.type
    local text = h.message_definition
    if (text == nil or text == "") and client.type == tname then text = client.message_definition end
    if (text == nil or text == "") and KNOWN.messages[tname] then
      text = KNOWN.messages[tname].definition
    end
    if text == nil or text == "" then
      return nil, "no message_definition for " .. tostring(tname)
    end
    return tname, parse_definition(tname, text)
  end
  local tname = h.type
  local known = tname and KNOWN.services[tname]
  if known == nil then
    return nil, "service type " .. tostring(tname) .. " is not in this dissector: headers "
      .. "carry no service definition (minros trace dissector --type " .. tostring(tname) .. ")"
  end
  local request = src == conn.client
  local part = request and "Request" or "Response"
  return tname .. part, parse_definition(tname .. part, request and known.request or known.response)
end

-- ------------------------------------------------------------------------------ PDUs

local function header_pdu(tvb, pinfo, tree, offset, size, conn, src, side)
  local sub = tree:add(proto, tvb(offset, math.min(4 + size, tvb:len() - offset)),
                       "TCPROS connection header")
  sub:add_le(pf.header, tvb(offset, 4))
  local pos, stop = offset + 4, offset + 4 + size
  local parsed, count = {}, 0
  while pos + 4 <= stop and pos + 4 <= tvb:len() do
    local n = tvb(pos, 4):le_uint()
    if pos + 4 + n > stop then
      sub:add_proto_expert_info(ex.malformed, "a field passes the end of the header")
      break
    end
    if pos + 4 + n > tvb:len() then
      sub:add_proto_expert_info(ex.truncated)
      break
    end
    local text = raw(tvb, pos + 4, n)
    local key, value = text:match("^([^=]*)=(.*)$")
    count = count + 1
    if key then
      parsed[key] = value
      local field = header_pf[key] or pf.header_field
      local item = sub:add(field, tvb(pos + 4 + #key + 1, #value), value)
      local shown = value
      if value:find("\n") then
        local lines = select(2, value:gsub("\n", "\n")) + 1
        shown = value:match("^[^\n]*") .. string.format("   (first line of %d)", lines)
      end
      item:set_text(key .. "=" .. cut(shown, 200))
      if key == "error" then item:add_proto_expert_info(ex.refused, value) end
    end
    pos = pos + 4 + n
  end
  if side == nil and not pinfo.visited then
    side = {frame = pinfo.number, offset = offset, fields = parsed, count = 0, numbers = {}}
    conn.sides[src] = side
    if conn.client == nil then conn.client = src end
  end
  local kind, name = kind_of(conn)
  local what = (src == conn.client) and "client" or "server"
  sub:set_text(string.format("TCPROS connection header (%s), %d bytes, %d field%s", what, size, count,
                             count == 1 and "" or "s"))
  local info = "Connection header " .. (parsed.callerid or "?")
  if parsed.error then info = info .. " refuses: " .. cut(parsed.error, 80)
  elseif kind and name then info = info .. ", " .. kind .. " " .. name end
  if parsed.type and parsed.type ~= "*" then info = info .. " [" .. parsed.type .. "]" end
  return info
end

local function frame_pdu(tvb, pinfo, tree, offset, size, conn, src, side, has_ok)
  local prefix = has_ok and 5 or 4
  local shown = math.min(prefix + size, tvb:len() - offset)
  local key = pinfo.number .. ":" .. offset
  local n = side.numbers[key]
  if n == nil then
    side.count = side.count + 1
    n = side.count
    side.numbers[key] = n
  end
  local kind, name = kind_of(conn)
  local noun = "Message"
  if kind == "service" then noun = (src == conn.client) and "Request" or "Response" end
  local sub = tree:add(proto, tvb(offset, shown), string.format("TCPROS %s %d", noun:lower(), n))
  sub:add(pf.number, at(tvb, offset), n):set_text(string.format(
    "Number on this connection: %d", n))
  local ok = nil
  if has_ok then
    ok = tvb(offset, 1):le_uint()
    sub:add(pf.ok, tvb(offset, 1)):set_text(string.format("ok: %d (%s)", ok,
      ok == 1 and "a response follows" or "an error text follows"))
  end
  sub:add_le(pf.length, tvb(offset + prefix - 4, 4))
  local start = offset + prefix
  local info = string.format("%s %d", noun, n)
  if name then info = info .. " on " .. name end
  if ok == 0 then
    local text = raw(tvb, start, math.min(size, tvb:len() - start))
    local range = #text > 0 and tvb(start, #text) or at(tvb, start)
    sub:add(pf.error_text, range, text):set_text("error: " .. quote(text))
    sub:set_text(string.format("TCPROS %s %d: ok=0, the service failed, %d bytes", noun:lower(),
                               n, size))
    return info .. ": error " .. quote(cut(text, 60))
  end
  local tname, def = frame_type(conn, src)
  if tname == nil or def.error then
    local why = tname == nil and def or def.error
    if size > 0 then sub:add(pf.body, tvb(start, math.max(0, shown - prefix))) end
    sub:add_proto_expert_info(ex.unknown, why)
    sub:set_text(string.format("TCPROS %s %d, %d bytes (not decoded: %s)", noun:lower(), n,
                               size, why))
    return info
  end
  sub:add(pf.msgtype, at(tvb, start), tname):set_text("Type: " .. tname)
  sub:set_text(string.format("TCPROS %s %d: %s, %d bytes", noun:lower(), n, tname, size))
  local body = new_body(tvb, start, size)
  local stop = decode_message(body, sub, def, def.types[def.core], start, 0)
  if body.bad then
    sub:add_proto_expert_info(ex.malformed, body.bad)
  elseif body.cut then
    sub:add_proto_expert_info(ex.truncated, string.format(
      "the capture holds %d of the %d bytes of this frame", shown - prefix, size))
  elseif stop and stop ~= start + size then
    sub:add_proto_expert_info(ex.malformed, string.format(
      "the message ends after %d bytes, the frame has %d", stop - start, size))
  end
  return info .. " (" .. tname .. ")"
end

function proto.dissector(tvb, pinfo, tree)
  local conn, src = conn_of(pinfo)
  local side = conn.sides[src]
  local reported = tvb:reported_len()
  local cut_by_capture = tvb:len() < reported
  local offset = 0
  local infos = {}
  pinfo.cols.protocol = "TCPROS"
  while offset < reported do
    local is_header = (side == nil and not pinfo.visited)
      or (side ~= nil and side.frame == pinfo.number and side.offset == offset)
    if side == nil and not is_header then return 0 end  -- a connection seen from its middle
    local has_ok = not is_header and kind_of(conn) == "service" and src ~= conn.client
    local prefix = has_ok and 5 or 4
    if reported - offset < prefix or offset + prefix > tvb:len() then
      if cut_by_capture then break end
      pinfo.desegment_offset = offset
      pinfo.desegment_len = DESEGMENT_ONE_MORE_SEGMENT
      return reported
    end
    local size = tvb(offset + prefix - 4, 4):le_uint()
    if is_header and (size > MAX_HEADER) then return 0 end
    if not cut_by_capture and offset + prefix + size > reported then
      pinfo.desegment_offset = offset
      pinfo.desegment_len = offset + prefix + size - reported
      return reported
    end
    if is_header then
      infos[#infos + 1] = header_pdu(tvb, pinfo, tree, offset, size, conn, src, side)
      side = conn.sides[src]
    else
      infos[#infos + 1] = frame_pdu(tvb, pinfo, tree, offset, size, conn, src, side, has_ok)
    end
    offset = offset + prefix + size
  end
  if #infos > 0 then
    pinfo.cols.info = infos[1] .. (#infos > 1 and string.format(" (+%d more)", #infos - 1) or "")
  end
  return reported
end

-- ------------------------------------------------------------------------ finding it

--- whether the bytes look like the start of a connection header
local function looks_like_header(tvb)
  local captured = tvb:len()
  if captured < 8 then return false end
  local size = tvb(0, 4):le_uint()
  if size < 6 or size > MAX_HEADER then return false end
  local pos, stop, count = 4, 4 + size, 0
  while pos < stop do
    if pos + 4 > captured then break end
    local n = tvb(pos, 4):le_uint()
    if n < 2 or pos + 4 + n > stop then return false end
    local take = math.min(n, captured - pos - 4, 64)
    if take <= 0 then break end
    -- a key is letters, digits and _, then "=" (within the bytes the capture has)
    if not tvb:raw(pos + 4, take):match("^[%w_]+=") and (take == n or take >= 32) then
      return false
    end
    count = count + 1
    pos = pos + 4 + n
  end
  return count > 0 and (pos == stop or pos >= captured)
end

local tcp_seq = Field.new("tcp.seq")  -- relative: 1 is a stream's first byte

local function heuristic(tvb, pinfo, tree)
  local seq = tcp_seq()
  if seq and seq.value ~= 1 then return false end  -- not the start of the stream
  if not looks_like_header(tvb) then return false end
  pinfo.conversation = proto
  proto.dissector(tvb, pinfo, tree)
  return true
end

proto:register_heuristic("tcp", heuristic)
