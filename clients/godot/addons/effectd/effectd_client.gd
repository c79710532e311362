# EffectdClient: asks a running effectd for effects over HTTP and turns the answers into Godot
# resources: an ArrayMesh for a bolt's ribbons or a bubble, an ImageTexture for a fog table.
# Godot 3.2+. Drop addons/effectd/ into a project; docs: clients/godot/README.md.
#
#   var client = EffectdClient.new()
#   add_child(client)                      # it makes its HTTPRequest nodes as children
#   client.base_url = "http://127.0.0.1:8080"
#   var r = yield(client.post("/v1/lightning", {...}), "completed")
#   if r.error: push_error("%s at %s" % [r.error.message, r.error.pointer])
#   else: $Bolt.mesh = EffectdClient.bolt_mesh(r.answer)
#
# Every result is {"answer": Dictionary or null, "error": null or Dictionary}. An error carries
# the HTTP status (0 when no answer came), the problem's title and detail, and the first
# offending field's JSON pointer and message ("/grid/width", "must be >= 3"): what a game shows
# or logs when a request it built is refused.
extends Node
class_name EffectdClient

var base_url := "http://127.0.0.1:8080"
var api_key := ""  # sent as "Authorization: Bearer <key>" when set (docs/serving.md)

# POSTs body (a Dictionary, sent as JSON) to path and yields its result (above).
func post(path: String, body: Dictionary):
	var http := HTTPRequest.new()
	add_child(http)
	var headers := ["Content-Type: application/json", "Accept: application/json"]
	if api_key != "":
		headers.append("Authorization: Bearer " + api_key)
	var sent := http.request(base_url + path, PoolStringArray(headers), true, HTTPClient.METHOD_POST, to_json(body))
	if sent != OK:
		http.queue_free()
		yield(get_tree(), "idle_frame")  # a coroutine on every path: callers always yield on it
		return _failure(0, "request not sent", "HTTPRequest.request returned error %d" % sent)
	var done = yield(http, "request_completed")  # [result, status, headers, body]
	http.queue_free()
	if done[0] != HTTPRequest.RESULT_SUCCESS:
		return _failure(0, "no answer", "HTTPRequest result %d (connection refused, timeout ...)" % done[0])
	var parsed := JSON.parse((done[3] as PoolByteArray).get_string_from_utf8())
	if parsed.error != OK or typeof(parsed.result) != TYPE_DICTIONARY:
		return _failure(done[1], "not JSON", "the answer is not a JSON object")
	if done[1] >= 400:
		var p: Dictionary = parsed.result
		var first: Dictionary = p.errors[0] if p.has("errors") and p.errors.size() > 0 else {}
		return {"answer": null, "error": {
			"status": done[1],
			"title": p.get("title", ""),
			"detail": p.get("detail", ""),
			"pointer": first.get("pointer", ""),
			"message": first.get("message", p.get("detail", "")),
		}}
	return {"answer": parsed.result, "error": null}

static func _failure(status: int, title: String, detail: String) -> Dictionary:
	return {"answer": null, "error": {"status": status, "title": title, "detail": detail, "pointer": "", "message": detail}}

# Flat [x, y, z, ...] -> PoolVector3Array (glTF and Godot share their axes: y up).
static func vec3s(flat: Array) -> PoolVector3Array:
	var out := PoolVector3Array()
	out.resize(flat.size() / 3)
	for i in range(out.size()):
		out[i] = Vector3(flat[3 * i], flat[3 * i + 1], flat[3 * i + 2])
	return out

static func vec2s(flat: Array) -> PoolVector2Array:
	var out := PoolVector2Array()
	out.resize(flat.size() / 2)
	for i in range(out.size()):
		out[i] = Vector2(flat[2 * i], flat[2 * i + 1])
	return out

# Surfaces are added uncompressed (compress flags 0): Godot's default keeps UVs in half floats,
# and a bolt's u runs along the channel in cells (steps of 1 past 1024), colours, normals and
# tangents in 8 bits.

# Triangles as Godot 3 draws them: its front faces wind clockwise, glTF's (and effectd's)
# counter-clockwise, so each triangle's last two corners swap.
static func clockwise(indices: Array) -> PoolIntArray:
	var out := PoolIntArray()
	out.resize(indices.size())
	for t in range(indices.size() / 3):
		out[3 * t] = int(indices[3 * t])
		out[3 * t + 1] = int(indices[3 * t + 2])
		out[3 * t + 2] = int(indices[3 * t + 1])
	return out

# A bolt asked with include ["mesh"]: one surface per primitive (main channel, branches), in
# the answer's order. COLOR is the intensity (grey, alpha 1), UV runs along (world units) and
# across (0 to 1) the ribbon. Draw additively, unshaded, without culling (docs/effects.md 1.8).
static func bolt_mesh(answer: Dictionary) -> ArrayMesh:
	var mesh := ArrayMesh.new()
	for p in answer.mesh.primitives:
		var arrays := []
		arrays.resize(Mesh.ARRAY_MAX)
		arrays[Mesh.ARRAY_VERTEX] = vec3s(p.positions)
		arrays[Mesh.ARRAY_TEX_UV] = vec2s(p.uvs)
		var colors := PoolColorArray()
		colors.resize(p.intensity.size())
		for i in range(colors.size()):
			colors[i] = Color(p.intensity[i], p.intensity[i], p.intensity[i], 1.0)
		arrays[Mesh.ARRAY_COLOR] = colors
		arrays[Mesh.ARRAY_INDEX] = clockwise(p.indices)
		mesh.add_surface_from_arrays(Mesh.PRIMITIVE_TRIANGLES, arrays, [], 0)  # uncompressed (below)
	return mesh

# A bubble asked with include ["mesh"] and uvOrigin "top-left" (Godot's UVs, like glTF's, have
# v down; Godot's scene shader takes the binormal as cross(normal, tangent) * tangent.w, as
# glTF does, so the tangents go in as they come).
static func bubble_mesh(answer: Dictionary) -> ArrayMesh:
	var m: Dictionary = answer.mesh
	var arrays := []
	arrays.resize(Mesh.ARRAY_MAX)
	arrays[Mesh.ARRAY_VERTEX] = vec3s(m.positions)
	arrays[Mesh.ARRAY_NORMAL] = vec3s(m.normals)
	arrays[Mesh.ARRAY_TEX_UV] = vec2s(m.uvs)
	arrays[Mesh.ARRAY_TANGENT] = PoolRealArray(m.tangents)
	arrays[Mesh.ARRAY_INDEX] = clockwise(m.indices)
	var mesh := ArrayMesh.new()
	mesh.add_surface_from_arrays(Mesh.PRIMITIVE_TRIANGLES, arrays, [], 0)  # uncompressed (below)
	return mesh

# A fog answer's table (answer.table, or one of answer.regionTables) as an image: size columns
# (distance from range[0] to range[1]) by elevations rows (1 unless HEIGHT), RGBA = (the fog's
# colour reaching the eye, f) as the server's texelLayout says. Encoding json gives a float
# image; rgba8 and rgba16f give the bytes as sent. Sample it with filtering on, and look a
# distance d up at u = (d - range[0]) / (range[1] - range[0]) (a warped HEIGHT table: its axes,
# docs/using/fog.md section 4).
static func fog_image(table: Dictionary) -> Image:
	var w := int(table.size)
	var h := int(table.get("elevations", 1))
	var image := Image.new()
	if table.encoding == "json":
		var bytes := StreamPeerBuffer.new()
		for i in range(w * h):
			for c in range(3):
				bytes.put_float(table.fogContribution[3 * i + c])
			bytes.put_float(table.factor[i])
		image.create_from_data(w, h, false, Image.FORMAT_RGBAF, bytes.data_array)
	else:
		var format := Image.FORMAT_RGBA8 if table.encoding == "rgba8" else Image.FORMAT_RGBAH
		image.create_from_data(w, h, false, format, Marshalls.base64_to_raw(table.data))
	return image

static func fog_texture(table: Dictionary) -> ImageTexture:
	var texture := ImageTexture.new()
	texture.create_from_image(fog_image(table), Texture.FLAG_FILTER)  # linear, no repeat, no mipmaps
	return texture
