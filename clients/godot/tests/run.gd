# The addon against a running effectd, headless (godot3-server): a bolt, a fog table (JSON and
# rgba8) and a bubble become an ArrayMesh and ImageTextures whose vertex counts, sizes and
# values are checked against the JSON answers, and a refused request reaches the game as an
# error naming the field. Exit status: 0 when every check holds.
#
#   godot3-server --path clients/godot -s res://tests/run.gd --effectd=http://127.0.0.1:8080
extends SceneTree

const EffectdClient = preload("res://addons/effectd/effectd_client.gd")

var failures := 0
var checks := 0

func check(ok: bool, what: String) -> void:
	checks += 1
	if not ok:
		failures += 1
		printerr("FAIL ", what)

func near(a: float, b: float, tolerance: float) -> bool:
	return abs(a - b) <= tolerance

func _init():
	call_deferred("run")

func run():
	var url := "http://127.0.0.1:8080"
	for arg in OS.get_cmdline_args():
		if arg.begins_with("--effectd="):
			url = arg.substr(len("--effectd="))
	var client = EffectdClient.new()
	client.base_url = url
	root.add_child(client)

	# A bolt as ribbons.
	var r = yield(client.post("/v1/lightning", {
		"grid": {"width": 48, "height": 48}, "start": [24, 0],
		"targetRegion": {"rows": [{"y": 47, "runs": [[0, 48]]}]},
		"include": ["mesh", "shape"], "seed": 3}), "completed")
	check(r.error == null, "lightning answered: %s" % str(r.error))
	if r.error == null:
		var mesh: ArrayMesh = EffectdClient.bolt_mesh(r.answer)
		var primitives: Array = r.answer.mesh.primitives
		check(mesh.get_surface_count() == primitives.size(), "one surface per primitive")
		for s in range(min(mesh.get_surface_count(), primitives.size())):
			var p: Dictionary = primitives[s]
			check(mesh.surface_get_array_len(s) == p.positions.size() / 3, "bolt surface %d vertices" % s)
			check(mesh.surface_get_array_index_len(s) == p.indices.size(), "bolt surface %d indices" % s)
			var arrays = mesh.surface_get_arrays(s)
			var v: Vector3 = arrays[Mesh.ARRAY_VERTEX][0]
			check(near(v.x, p.positions[0], 1e-4) and near(v.y, p.positions[1], 1e-4) and near(v.z, p.positions[2], 1e-4), "bolt vertex 0 as sent")
			var last := int(p.intensity.size()) - 1
			check(near(arrays[Mesh.ARRAY_COLOR][last].r, p.intensity[last], 1e-6), "bolt intensity as colour (float)")
			check(near(arrays[Mesh.ARRAY_TEX_UV][last].x, p.uvs[2 * last], 1e-6), "bolt u along the channel, float")
			var idx: PoolIntArray = arrays[Mesh.ARRAY_INDEX]
			check(idx[1] == int(p.indices[2]) and idx[2] == int(p.indices[1]), "triangles wound clockwise for Godot")
		check(r.answer.struck[1] == 47, "the bolt struck the ground row")
		print("bolt: %d surfaces, %d cells, %d tips" % [mesh.get_surface_count(), r.answer.shape.cells, r.answer.shape.tips])

	# A fog table, as floats and as bytes.
	for encoding in ["json", "rgba8"]:
		r = yield(client.post("/v1/fog", {
			"fog": {"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "color": [0.6, 0.65, 0.7]},
			"table": {"size": 32, "elevations": 8, "range": [0, 200], "cameraHeight": 2, "encoding": encoding}}), "completed")
		check(r.error == null, "fog (%s) answered: %s" % [encoding, str(r.error)])
		if r.error != null:
			continue
		var table: Dictionary = r.answer.table
		var texture: ImageTexture = EffectdClient.fog_texture(table)
		check(texture.get_width() == 32 and texture.get_height() == 8, "fog texture 32 x 8 (%s)" % encoding)
		var image: Image = texture.get_data()
		image.lock()
		if encoding == "json":
			for i in [0, 5, 100, 255]:
				var texel: Color = image.get_pixel(i % 32, i / 32)
				check(near(texel.a, table.factor[i], 1e-6), "f at texel %d" % i)
				check(near(texel.g, table.fogContribution[3 * i + 1], 1e-6), "fog colour (green) at texel %d" % i)
		else:
			var bytes: PoolByteArray = Marshalls.base64_to_raw(table.data)
			for i in [0, 37, 255]:
				var texel: Color = image.get_pixel(i % 32, i / 32)
				check(texel.a8 == bytes[4 * i + 3] and texel.r8 == bytes[4 * i], "rgba8 texel %d as sent" % i)
		image.unlock()
	print("fog: textures checked")

	# A bubble mesh.
	r = yield(client.post("/v1/bubble", {"include": ["mesh"], "uvOrigin": "top-left"}), "completed")
	check(r.error == null, "bubble answered: %s" % str(r.error))
	if r.error == null:
		var mesh: ArrayMesh = EffectdClient.bubble_mesh(r.answer)
		check(mesh.surface_get_array_len(0) == int(r.answer.mesh.vertexCount), "bubble vertices")
		check(mesh.surface_get_array_index_len(0) == r.answer.mesh.indices.size(), "bubble indices")
		var arrays = mesh.surface_get_arrays(0)
		# Uncompressed: the normals are the float32s sent (Godot's default would keep 8 bits).
		var n: Vector3 = arrays[Mesh.ARRAY_NORMAL][7]
		var sent: Array = r.answer.mesh.normals
		check(near(n.x, sent[21], 1e-6) and near(n.y, sent[22], 1e-6) and near(n.z, sent[23], 1e-6), "normal 7 as sent, %s" % str(n))
		var uv: Vector2 = arrays[Mesh.ARRAY_TEX_UV][11]
		check(near(uv.x, r.answer.mesh.uvs[22], 1e-6) and near(uv.y, r.answer.mesh.uvs[23], 1e-6), "uv 11 as sent")
		check(near(arrays[Mesh.ARRAY_TANGENT][3], r.answer.mesh.tangents[3], 1e-6), "tangent sign as sent")
		print("bubble: %d vertices" % mesh.surface_get_array_len(0))

	# A refused request: the game gets the status and the field.
	r = yield(client.post("/v1/lightning", {"grid": {"width": 2, "height": 48}, "start": [0, 0], "targets": [[1, 47]]}), "completed")
	check(r.answer == null and r.error != null, "a 400 is an error")
	if r.error != null:
		check(r.error.status == 400, "status 400, got %s" % str(r.error.status))
		check(r.error.pointer == "/grid/width", "pointer /grid/width, got %s" % r.error.pointer)
		print("refused: %s %s" % [r.error.pointer, r.error.message])

	# No server at all: an error, not a hang.
	client.base_url = "http://127.0.0.1:1"
	r = yield(client.post("/v1/fog", {"fog": {"fogType": "LINEAR"}}), "completed")
	check(r.error != null and r.error.status == 0, "no server: status 0")

	# The README's snippets, where the test driver put them (tests/godot/client_test.sh): each
	# must add a MeshInstance with a mesh (the bolt, the bubble).
	var n := 1
	while ResourceLoader.exists("res://tests/readme_snippet_%d.gd" % n):
		var scene := Spatial.new()
		scene.set_script(load("res://tests/readme_snippet_%d.gd" % n))
		root.add_child(scene)
		var drawn: MeshInstance = null
		for frame in range(600):
			yield(self, "idle_frame")
			for child in scene.get_children():
				if child is MeshInstance:
					drawn = child
			if drawn:
				break
		check(drawn != null and drawn.mesh.get_surface_count() >= 1, "the README's snippet %d draws" % n)
		print("readme snippet %d: %s" % [n, "a mesh of %d surfaces" % drawn.mesh.get_surface_count() if drawn else "nothing"])
		n += 1
	check(n > 2, "the README's two snippets ran")

	print("%d checks, %d failed" % [checks, failures])
	quit(1 if failures else 0)
