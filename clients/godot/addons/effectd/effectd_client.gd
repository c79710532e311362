# EffectdClient: asks a running effectd for effects over HTTP and turns the answers into Godot
# resources and nodes: an ArrayMesh for a bolt's ribbons or a bubble, an ImageTexture for a fog
# table; a bolt that plays its strike, a shaded soap bubble, and a full-screen fog pass.
# Godot 3.2+ (the shaders need the GLES3 renderer). Drop addons/effectd/ into a project; docs:
# clients/godot/README.md.
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

const BoltNode = preload("effectd_bolt.gd")
const BoltShader = preload("effectd_bolt.shader")
const BubbleShader = preload("effectd_bubble.shader")
const FogShader = preload("effectd_fog.shader")

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
# across (0 to 1) the ribbon; with include "timeline", UV2 is (leader arrival, stroke delay) in
# seconds. Draw additively, unshaded, without culling (docs/effects.md 1.8), or use bolt().
static func bolt_mesh(answer: Dictionary) -> ArrayMesh:
	var mesh := ArrayMesh.new()
	for p in answer.mesh.primitives:
		var arrays := []
		arrays.resize(Mesh.ARRAY_MAX)
		arrays[Mesh.ARRAY_VERTEX] = vec3s(p.positions)
		arrays[Mesh.ARRAY_TEX_UV] = vec2s(p.uvs)
		if p.has("leader"):
			var timing := PoolVector2Array()
			timing.resize(p.leader.size())
			for i in range(timing.size()):
				timing[i] = Vector2(p.leader[i], p.strokeDelay[i])
			arrays[Mesh.ARRAY_TEX_UV2] = timing
		var colors := PoolColorArray()
		colors.resize(p.intensity.size())
		for i in range(colors.size()):
			colors[i] = Color(p.intensity[i], p.intensity[i], p.intensity[i], 1.0)
		arrays[Mesh.ARRAY_COLOR] = colors
		arrays[Mesh.ARRAY_INDEX] = clockwise(p.indices)
		mesh.add_surface_from_arrays(Mesh.PRIMITIVE_TRIANGLES, arrays, [], 0)  # uncompressed (below)
	return mesh

# A bolt that plays its strike (effectd_bolt.gd): a MeshInstance whose surfaces draw with
# effectd_bolt.shader; set its `time`, or play(). color: the channel's colour (display values).
static func bolt(answer: Dictionary, color := Color(0.75, 0.85, 1.0)) -> MeshInstance:
	var node = BoltNode.new()
	node.mesh = bolt_mesh(answer)
	var timeline = answer.get("timeline")
	var keys: ImageTexture = null
	if timeline:
		var k: Dictionary = timeline.keyframes
		var bytes := StreamPeerBuffer.new()
		for i in range(k.t.size()):
			for value in [k.t[i], k.leader[i], k.main[i], k.branches[i]]:
				bytes.put_float(value)
		var image := Image.new()
		image.create_from_data(k.t.size(), 1, false, Image.FORMAT_RGBAF, bytes.data_array)
		keys = ImageTexture.new()
		keys.create_from_image(image, 0)  # texelFetch: no filter, no mipmaps
		node.duration = timeline.duration
	for s in range(node.mesh.get_surface_count()):
		var material := ShaderMaterial.new()
		material.shader = BoltShader
		material.set_shader_param("timed", timeline != null)
		material.set_shader_param("main_channel", answer.mesh.primitives[s].channel == "main")
		material.set_shader_param("color", Vector3(color.r, color.g, color.b))
		if timeline:
			material.set_shader_param("keys", keys)
			material.set_shader_param("key_count", timeline.keyframes.t.size())
			material.set_shader_param("connect", timeline.connect)
		node.mesh.surface_set_material(s, material)
	node.extra_cull_margin = 16384.0  # the ribbons move nothing, but a strike is never culled half-lit
	return node

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

# A bubble shaded as a soap film (effectd_bubble.shader): asked with include ["mesh",
# "uniforms", "shader", "thinFilm", "thickness"], uvOrigin "top-left", thinFilm.encoding
# "rgba16f" and film.encoding "r32f" (the film shading, the default; "thickness" only where the
# answer's shader reads uThicknessField). environment: the sky the film mirrors, a CubeMap; null:
# a sky of one colour (the material's sky_color). Returns null, with an error pushed, for an
# answer it cannot draw.
static func bubble(answer: Dictionary, environment: CubeMap = null) -> MeshInstance:
	for part in ["mesh", "uniforms", "shader", "thinFilm"]:
		if not answer.has(part):
			push_error("effectd bubble: the answer has no %s: ask for include [\"mesh\", \"uniforms\", \"shader\", \"thinFilm\", \"thickness\"]" % part)
			return null
	if not "uPass" in answer.shader.uniforms:
		push_error("effectd bubble: the Godot addon draws the film shading (shading \"film\")")
		return null
	var field: bool = "uThicknessField" in answer.shader.uniforms
	if field and not answer.has("thickness"):
		push_error("effectd bubble: the answer's shader reads the thickness field: include \"thickness\"")
		return null
	var node := MeshInstance.new()
	node.mesh = bubble_mesh(answer)
	var table := Image.new()
	table.create_from_data(int(answer.thinFilm.width), int(answer.thinFilm.height), false, Image.FORMAT_RGBAH,
			Marshalls.base64_to_raw(answer.thinFilm.data))
	var thin_film := ImageTexture.new()
	thin_film.create_from_image(table, Texture.FLAG_FILTER)
	var thickness: ImageTexture = null
	if field:  # filled by bubble_update below
		thickness = ImageTexture.new()
		thickness.create(int(answer.thickness.width), int(answer.thickness.height), Image.FORMAT_RH,
				Texture.FLAG_FILTER | Texture.FLAG_REPEAT)  # u wraps around the sphere
	# The far side (cull_front) then the near side, each what passes (blend_mul) then what it
	# reflects (blend_add), as the answer's shader.draw says; without features.backFace only the near.
	var sides := ["cull_front", "cull_back"] if answer.shader.draw.begins_with("back faces") else ["cull_back"]
	var first: ShaderMaterial = null
	var last: ShaderMaterial = null
	for side in sides:
		for step in [0, 1]:
			var material := ShaderMaterial.new()
			material.shader = _bubble_variant("blend_mul" if step == 0 else "blend_add", side)
			material.set_shader_param("film_pass", step)
			material.set_shader_param("thin_film", thin_film)
			material.set_shader_param("use_thickness_field", field)
			if field:
				material.set_shader_param("thickness_field", thickness)
			material.set_shader_param("use_environment", environment != null)
			if environment:
				material.set_shader_param("environment", environment)
			material.render_priority = (0 if first == null else last.render_priority + 1)
			if last:
				last.next_pass = material
			else:
				first = material
			last = material
	node.material_override = first
	bubble_update(node, answer)
	return node

# The four film shaders made once (kept on the shared resource): a new bubble compiles nothing.
static func _bubble_variant(blend: String, side: String) -> Shader:
	var key := "effectd_%s_%s" % [blend, side]
	if not BubbleShader.has_meta(key):
		var shader := Shader.new()
		shader.code = BubbleShader.code.replace("blend_add, cull_back", "%s, %s" % [blend, side])
		BubbleShader.set_meta(key, shader)
	return BubbleShader.get_meta(key)

# A later answer's uniforms (a new time: wobble phase, thickness, lights) into bubble()'s materials.
static func bubble_update(node: MeshInstance, answer: Dictionary) -> void:
	var u: Dictionary = answer.uniforms
	var material: ShaderMaterial = node.material_override
	while material:
		if u.has("uThicknessRange"):
			material.set_shader_param("thickness_range", Vector2(u.uThicknessRange[0], u.uThicknessRange[1]))
		if u.has("uThicknessNm"):
			material.set_shader_param("thickness_nm", u.uThicknessNm)
		var lights := int(min(u.get("uLightCount", 0), 4))
		material.set_shader_param("light_count", lights)
		for i in range(lights):
			material.set_shader_param("light%d_direction" % i, Vector3(u.uLightDirection[i][0], u.uLightDirection[i][1], u.uLightDirection[i][2]))
			material.set_shader_param("light%d_radiance" % i, Vector3(u.uLightRadiance[i][0], u.uLightRadiance[i][1], u.uLightRadiance[i][2]))
			material.set_shader_param("light%d_sharpness" % i, u.uLightSharpness[i])
		for name in ["Phase", "Amplitude", "Frequency"]:
			if u.has("uWobble" + name):
				material.set_shader_param("wobble_" + name.to_lower(), u["uWobble" + name])
		material = material.next_pass
	if answer.has("thickness") and node.material_override.get_shader_param("use_thickness_field"):
		var image := Image.new()  # row 0 at v = 0, as Godot reads an image's first row
		image.create_from_data(int(answer.thickness.width), int(answer.thickness.height), false, Image.FORMAT_RF,
				Marshalls.base64_to_raw(answer.thickness.data))
		image.convert(Image.FORMAT_RH)  # half floats filter everywhere (mobile GLES3 may not filter floats)
		node.material_override.get_shader_param("thickness_field").set_data(image)

# Fog over the whole view (effectd_fog.shader): a full-screen quad that fogs what is drawn by
# its depth, from a fog answer's `table` (any encoding; HEIGHT tables linear or warped; the
# global fog only: regionTables, ATMOSPHERIC's per-channel transmittance and the directional
# glow are not drawn). It draws first among see-through objects (lowest render_priority) and
# fogs the opaque scene; see-through objects drawn after it (bolts, bubbles) are not fogged.
static func fog_overlay(table: Dictionary) -> MeshInstance:
	var quad := QuadMesh.new()
	quad.size = Vector2(2, 2)
	var material := ShaderMaterial.new()
	material.shader = FogShader
	material.set_shader_param("fog_table", fog_texture(table))
	material.set_shader_param("fog_range", Vector2(table.range[0], table.range[1]))
	material.set_shader_param("fog_texels", Vector2(table.size, table.get("elevations", 1)))
	if table.has("cutoffDistance"):
		material.set_shader_param("fog_cutoff", table.cutoffDistance)
	if table.has("axes"):
		var a: Dictionary = table.axes
		material.set_shader_param("fog_warp", Plane(a.k, a.falloff, a.kappa, a["lambda"]))  # a vec4
		material.set_shader_param("fog_warp_range", Vector2(a.factorStart, a.end))
	var node := MeshInstance.new()
	node.mesh = quad
	material.render_priority = Material.RENDER_PRIORITY_MIN
	quad.custom_aabb = AABB(Vector3.ONE * -1e7, Vector3.ONE * 2e7)  # placed by its shader: never culled
	node.material_override = material
	return node
