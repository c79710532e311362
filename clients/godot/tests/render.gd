# The addon's shaders drawn by Godot 3's own renderer (GLES3; headless under Xvfb on Mesa's
# llvmpipe), each picture read back and checked against numbers from outside the shader:
# - the strike (effectd_bolt.shader): black before the leader sets off and after the strike,
#   the leader growing, then the main channel's brightness as the answer's keyframes say;
# - the soap film (effectd_bubble.shader): pixels across the bubble against the film's two
#   sides composited by hand from the thin-film table at each side's angle and thickness (ray
#   and sphere intersected here, the thickness field read from the answer's bytes);
# - the fog (effectd_fog.shader): pixels on a floor and a wall against the server's exact
#   per-point `samples` at the points those pixels see.
# Exit status: 0 when every check holds.
#
#   xvfb-run godot3 --path clients/godot -s res://tests/render.gd --resolution 256x256 \
#     --effectd=http://127.0.0.1:8080 [--png=FOLDER (every frame read back, to look at)]
extends SceneTree

const EffectdClient = preload("res://addons/effectd/effectd_client.gd")

var failures := 0
var checks := 0
var png_folder := ""
var frames := 0

func check(ok: bool, what: String) -> void:
	checks += 1
	if not ok:
		failures += 1
		printerr("FAIL ", what)

static func linear(c: float) -> float:  # the window's sRGB bytes back to linear
	return c / 12.92 if c <= 0.04045 else pow((c + 0.055) / 1.055, 2.4)

func _init():
	call_deferred("run")

# The next frame Godot draws, as an image with row 0 at the top.
func grab():
	for i in range(3):
		yield(VisualServer, "frame_post_draw")
	var image: Image = root.get_texture().get_data()
	image.flip_y()
	if png_folder != "":
		frames += 1
		image.save_png("%s/frame-%02d.png" % [png_folder, frames])
	image.lock()
	return image

func summed(image: Image) -> Dictionary:
	var total := 0.0
	var lit := 0
	var brightest := 0.0
	for y in range(image.get_height()):
		for x in range(image.get_width()):
			var v := linear(image.get_pixel(x, y).r)
			total += v
			brightest = max(brightest, v)
			lit += 1 if v > 0.0 else 0
	return {"total": total, "lit": lit, "max": brightest}

# (leader, main, branches) at t, linear between the keyframes: the timeline's own rule.
static func channels(k: Dictionary, t: float) -> Vector3:
	var n: int = k.t.size()
	if t < k.t[0] or t > k.t[n - 1]:
		return Vector3()
	for i in range(n - 1):
		if t <= k.t[i + 1]:
			var a: float = (t - k.t[i]) / max(k.t[i + 1] - k.t[i], 1e-30)
			return Vector3(lerp(k.leader[i], k.leader[i + 1], a), lerp(k.main[i], k.main[i + 1], a),
					lerp(k.branches[i], k.branches[i + 1], a))
	return Vector3()

func run():
	var url := "http://127.0.0.1:8080"
	for arg in OS.get_cmdline_args():
		if arg.begins_with("--effectd="):
			url = arg.substr(len("--effectd="))
		if arg.begins_with("--png="):
			png_folder = arg.substr(len("--png="))
	var client = EffectdClient.new()
	client.base_url = url
	root.add_child(client)
	VisualServer.set_default_clear_color(Color(0, 0, 0))
	var camera := Camera.new()
	root.add_child(camera)
	camera.current = true
	yield(strike(client, camera), "completed")
	yield(film(client, camera), "completed")
	yield(fog(client, camera), "completed")
	print("%d checks, %d failed" % [checks, failures])
	quit(1 if failures else 0)

func strike(client, camera: Camera):
	var r = yield(client.post("/v1/lightning", {
		"grid": {"width": 48, "height": 48}, "start": [24, 0],
		"targetRegion": {"rows": [{"y": 47, "runs": [[0, 48]]}]},
		"include": ["mesh", "timeline"], "seed": 3}), "completed")
	check(r.error == null, "lightning answered: %s" % str(r.error))
	if r.error:
		return
	var bolt: MeshInstance = EffectdClient.bolt(r.answer, Color(1, 1, 1))
	root.add_child(bolt)
	var box: AABB = bolt.mesh.get_aabb()
	camera.set_orthogonal(max(box.size.x, box.size.y) * 1.1, 1.0, 100.0)
	camera.translation = box.position + box.size * 0.5 + Vector3(0, 0, 50)
	var timeline: Dictionary = r.answer.timeline
	var k: Dictionary = timeline.keyframes
	var seen := {}
	for t in [-1.0, 0.5 * timeline.connect, 0.98 * timeline.connect, timeline.duration + 0.01]:
		bolt.time = t
		seen[t] = summed(yield(grab(), "completed"))
	check(seen[-1.0].lit == 0, "dark before the leader sets off (%d pixels lit)" % seen[-1.0].lit)
	check(seen[timeline.duration + 0.01].lit == 0, "dark after the strike")
	var half: Dictionary = seen[0.5 * timeline.connect]
	var whole: Dictionary = seen[0.98 * timeline.connect]
	check(half.lit > 0 and half.lit < 0.8 * whole.lit, "the leader grows: %d then %d pixels" % [half.lit, whole.lit])
	# The main channel alone (branches black): its light follows the main keyframes. Two times
	# on the decay after the peak, long after every vertex's return stroke has arrived.
	bolt.mesh.surface_get_material(1).set_shader_param("color", Vector3())
	var peak := 0
	for i in range(k.t.size()):
		if k.main[i] > k.main[peak]:
			peak = i
	var times := []
	var i := peak
	for share in [0.75, 0.35]:
		while i < k.t.size() - 1 and k.main[i] > share * k.main[peak]:
			i += 1
		times.append(0.5 * (k.t[i - 1] + k.t[i]))
	check(times[0] > timeline.connect + 0.001, "the first time is after every return stroke (%.4f)" % times[0])
	var light := []
	for t in times:
		bolt.time = t
		light.append(summed(yield(grab(), "completed")).total)  # additive ribbons: light sums
	var expected: float = channels(k, times[1]).y / channels(k, times[0]).y
	var measured: float = light[1] / max(light[0], 1e-9)
	check(abs(measured / expected - 1.0) < 0.05, "main channel at t %.4f / t %.4f: %.4f, keyframes say %.4f" % [times[1], times[0], measured, expected])
	print("strike: leader %d then %d pixels; main channel light ratio %.4f (keyframes %.4f)" % [half.lit, whole.lit, measured, expected])
	bolt.queue_free()

# The thin-film table's reflectance at (u, cos theta), bilinear between texel centres.
static func reflectance(table: Image, u: float, c: float) -> Color:
	var x: float = clamp(u, 0.0, 1.0) * (table.get_width() - 1)
	var y: float = clamp(c, 0.0, 1.0) * (table.get_height() - 1)
	var x0: int = int(min(floor(x), table.get_width() - 2))
	var y0: int = int(min(floor(y), table.get_height() - 2))
	var fx: float = x - x0
	var fy: float = y - y0
	var top: Color = table.get_pixel(x0, y0).linear_interpolate(table.get_pixel(x0 + 1, y0), fx)
	var bottom: Color = table.get_pixel(x0, y0 + 1).linear_interpolate(table.get_pixel(x0 + 1, y0 + 1), fx)
	return top.linear_interpolate(bottom, fy)

# The thickness field's nm at a point of the unit sphere, bilinear, as the answer's thickness.axes
# say (equirectangular: u = atan2(z, x) / 2 pi + 0.5 wrapping, v = acos(-y) / pi from row 0 at
# the bottom), read from the answer's bytes, not from the addon's texture.
static func thickness_at(field: Image, p: Vector3) -> float:
	var w := field.get_width()
	var h := field.get_height()
	var x: float = (atan2(p.z, p.x) / (2.0 * PI) + 0.5) * w - 0.5
	var y: float = clamp(acos(clamp(-p.y, -1.0, 1.0)) / PI * h - 0.5, 0.0, h - 1.001)
	var x0 := int(floor(x))
	var y0 := int(floor(y))
	var fx: float = x - x0
	var fy: float = y - y0
	var a: float = lerp(field.get_pixel(posmod(x0, w), y0).r, field.get_pixel(posmod(x0 + 1, w), y0).r, fx)
	var b: float = lerp(field.get_pixel(posmod(x0, w), y0 + 1).r, field.get_pixel(posmod(x0 + 1, w), y0 + 1).r, fx)
	return lerp(a, b, fy)

# The film over a blue background and a grey sky: one thickness for the whole film (pixels along
# the equator), then the drainage-and-swirl field (pixels up the middle, where the thickness
# changes fastest).
func film(client, camera: Camera):
	for with_field in [false, true]:
		yield(film_case(client, camera, with_field), "completed")

func film_case(client, camera: Camera, with_field: bool):
	var include := ["mesh", "uniforms", "shader", "thinFilm"] + (["thickness"] if with_field else [])
	var r = yield(client.post("/v1/bubble", {
		"include": include, "uvOrigin": "top-left",
		"features": {"wobble": false, "thickness": with_field, "highlight": false},
		"shader": {"language": "glsl-es-300"}, "thinFilm": {"encoding": "rgba16f"}, "film": {"encoding": "r32f"}}), "completed")
	check(r.error == null, "bubble answered: %s" % str(r.error))
	if r.error:
		return
	var sky := Vector3(0.9, 0.9, 0.9)
	var bubble: MeshInstance = EffectdClient.bubble(r.answer)
	var material: ShaderMaterial = bubble.material_override
	var passes := 0
	while material:
		material.set_shader_param("sky_color", sky)
		material = material.next_pass
		passes += 1
	check(passes == 4, "four draws: far side and near side, each multiplied then added (%d)" % passes)
	var centre := Vector3(0, 0, -4)
	bubble.translation = centre
	root.add_child(bubble)
	camera.set_perspective(60.0, 0.1, 100.0)
	camera.translation = Vector3()
	VisualServer.set_default_clear_color(Color(0.1, 0.2, 0.5))
	var image: Image = yield(grab(), "completed")
	var back: Color = image.get_pixel(2, 2)
	var behind := Vector3(linear(back.r), linear(back.g), linear(back.b))
	var table := Image.new()
	table.create_from_data(int(r.answer.thinFilm.width), int(r.answer.thinFilm.height), false, Image.FORMAT_RGBAH,
			Marshalls.base64_to_raw(r.answer.thinFilm.data))
	table.lock()
	var field := Image.new()
	if with_field:
		field.create_from_data(int(r.answer.thickness.width), int(r.answer.thickness.height), false, Image.FORMAT_RF,
				Marshalls.base64_to_raw(r.answer.thickness.data))
		field.lock()
	var range_nm: Array = r.answer.uniforms.uThicknessRange
	var radius := 0.0
	for p in EffectdClient.vec3s(r.answer.mesh.positions):
		radius = max(radius, p.length())
	var worst := 0.0
	var tried := 0
	var cosines := []
	var middle := Vector2(image.get_width() / 2, image.get_height() / 2)
	var step := Vector2(0, -6) if with_field else Vector2(6, 0)
	var pixel := middle
	while pixel.x < image.get_width() and pixel.y >= 0:
		var from := camera.project_ray_origin(pixel + Vector2(0.5, 0.5))
		var ray := camera.project_ray_normal(pixel + Vector2(0.5, 0.5))
		var to := centre - from
		var b := ray.dot(to)
		var disc := b * b - to.length_squared() + radius * radius
		if disc <= 0.0:
			break
		var near := (from + ray * (b - sqrt(disc)) - centre) / radius
		var far := (from + ray * (b + sqrt(disc)) - centre) / radius
		var cos_near: float = abs(ray.dot(near))
		if cos_near < 0.35:  # the silhouette: the mesh's facets, not the film, decide there
			break
		var nm_near: float = thickness_at(field, near) if with_field else r.answer.uniforms.uThicknessNm
		var nm_far: float = thickness_at(field, far) if with_field else r.answer.uniforms.uThicknessNm
		var rf := reflectance(table, (nm_near - range_nm[0]) / (range_nm[1] - range_nm[0]), cos_near)
		var rb := reflectance(table, (nm_far - range_nm[0]) / (range_nm[1] - range_nm[0]), abs(ray.dot(far)))
		var seen: Color = image.get_pixel(int(pixel.x), int(pixel.y))
		for c in range(3):
			var through: float = behind[c] * (1.0 - rb[c]) + rb[c] * sky[c]
			var expected: float = through * (1.0 - rf[c]) + rf[c] * sky[c]
			worst = max(worst, abs(linear(seen[c]) - expected))
		cosines.append(cos_near)
		tried += 1
		pixel += step
	var what := "the thickness field" if with_field else "one thickness"
	var tolerance := 0.02 if with_field else 0.012  # the field: UVs interpolated over the mesh's facets
	check(tried >= 5, "pixels across the bubble (%d)" % tried)
	check(worst < tolerance, "the film's colour (%s) as its two sides composite: worst %.4f (linear)" % [what, worst])
	print("film, %s: %d pixels from cos %.2f to %.2f, worst %.4f from the table composited by hand" % [what, tried, cosines[0] if tried else 0.0, cosines[-1] if tried else 0.0, worst])
	bubble.queue_free()
	VisualServer.set_default_clear_color(Color(0, 0, 0))

func fog(client, camera: Camera):
	var white := SpatialMaterial.new()
	white.flags_unshaded = true
	white.albedo_color = Color(1, 1, 1)
	var floor_mesh := PlaneMesh.new()  # y = 0, up
	floor_mesh.size = Vector2(400, 400)
	var floor_node := MeshInstance.new()
	floor_node.mesh = floor_mesh
	floor_node.material_override = white
	floor_node.translation = Vector3(0, 0, -100)
	var wall_mesh := QuadMesh.new()  # z = -35, facing the camera
	wall_mesh.size = Vector2(400, 80)
	var wall := MeshInstance.new()
	wall.mesh = wall_mesh
	wall.material_override = white
	wall.translation = Vector3(0, 40, -35)
	root.add_child(floor_node)
	root.add_child(wall)
	camera.set_perspective(70.0, 0.1, 500.0)
	camera.translation = Vector3(0, 3, 0)
	camera.rotation_degrees = Vector3(-10, 15, 0)  # pitched and turned: view and world axes differ
	# The points the chosen pixels see, worked out here from the rays and the two planes.
	var pixels := [Vector2(128, 30), Vector2(128, 110), Vector2(128, 150), Vector2(128, 235), Vector2(20, 200), Vector2(240, 60), Vector2(10, 140)]
	var points := []
	for p in pixels:
		var from := camera.project_ray_origin(p + Vector2(0.5, 0.5))
		var ray := camera.project_ray_normal(p + Vector2(0.5, 0.5))
		var t := (-35.0 - from.z) / ray.z
		if ray.y < 0.0:
			t = min(t, -from.y / ray.y)
		var at := from + ray * t
		points.append([at.x, at.y, at.z])
	var color := [0.6, 0.65, 0.7]
	var r = yield(client.post("/v1/fog", {
		"fog": {"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "color": color},
		"table": {"size": 64, "elevations": 32, "range": [0, 200], "cameraHeight": 3, "encoding": "json"},
		"include": ["table", "samples"], "samples": {"camera": [0, 3, 0], "points": points}}), "completed")
	check(r.error == null, "fog answered: %s" % str(r.error))
	if r.error:
		return
	var table: Dictionary = r.answer.table
	check(table.layout == "warped", "a warped HEIGHT table (the default)")
	for i in [0, 700, 2047]:  # what reaches the eye from the fog is its colour times (1 - f)
		check(abs(table.fogContribution[3 * i] - color[0] * (1.0 - table.factor[i])) < 1e-4, "S = colour (1 - f) at texel %d" % i)
	var overlay: MeshInstance = EffectdClient.fog_overlay(table)
	root.add_child(overlay)
	var image: Image = yield(grab(), "completed")
	var worst := 0.0
	for i in range(pixels.size()):
		var f: float = r.answer.samples[i].factor
		var seen: Color = image.get_pixel(int(pixels[i].x), int(pixels[i].y))
		for c in range(3):
			worst = max(worst, abs(linear(seen[c]) - (f + color[c] * (1.0 - f))))
	var tolerance: float = table.maxError + 0.01  # the table's own error, and 8-bit sRGB steps
	check(worst < tolerance, "fogged pixels against the exact samples: worst %.4f, allowed %.4f" % [worst, tolerance])
	var bare: Color = image.get_pixel(128, 235)
	overlay.visible = false
	var unfogged: Image = yield(grab(), "completed")
	check(unfogged.get_pixel(128, 235).r > 0.99 and bare.r < 0.99, "the fog pass is what darkens the floor")
	print("fog: %d pixels against the server's samples, worst %.4f (table maxError %.4f)" % [pixels.size(), worst, table.maxError])
	for node in [overlay, floor_node, wall]:
		node.queue_free()
