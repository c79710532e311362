# A bolt from /v1/lightning as a MeshInstance that plays its strike: made by
# EffectdClient.bolt(answer) from an answer with include ["mesh", "timeline"] (without
# "timeline" the whole bolt shows at its intensity). Set `time` (seconds since the leader set
# off, the answer's timeline times) from your own clock, or call play() and let _process run it
# once. Draws with effectd_bolt.shader: additive, unshaded, both sides.
extends MeshInstance

var duration := 0.0       # the strike's length (timeline.duration), 0 without a timeline
var playing := false
var time := 0.0 setget set_time

func set_time(t: float) -> void:
	time = t
	for s in range(mesh.get_surface_count() if mesh else 0):
		mesh.surface_get_material(s).set_shader_param("time", t)

# Plays the strike from its start, once, in game time.
func play() -> void:
	set_time(0.0)
	playing = true

func _process(delta: float) -> void:
	if playing:
		set_time(time + delta)
		playing = time <= duration
