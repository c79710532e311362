// A bolt's ribbon, and its strike played from the answer's timeline (docs/effects.md §1.6), per
// vertex: dark before the leader reaches it (or if it never does), the leader channel until its
// return stroke arrives, then the main or the branches channel at time - stroke_delay; times the
// vertex's intensity. The same rule as clients/three/effectd-three.js. EffectdClient.bolt()
// sets the uniforms; EffectdBolt.time moves the strike.
//
// Mesh (EffectdClient.bolt_mesh): COLOR.r the intensity, UV (along, across) the ribbon,
// UV2 (leader arrival, stroke delay) in seconds.
shader_type spatial;
render_mode unshaded, blend_add, cull_disabled, depth_draw_never, shadows_disabled;

uniform sampler2D keys;        // key_count x 1 texels, RGBA = (t, leader, main, branches); no filter
uniform int key_count = 0;
uniform bool timed = false;    // false: the whole bolt at its intensity, no strike
uniform bool main_channel = true;
uniform float time = 0.0;      // seconds since the leader set off
uniform float connect = 0.0;   // when the leader touches the target
uniform vec3 color = vec3(0.75, 0.85, 1.0);

varying float brightness;

vec4 key_at(int i) {
	return texelFetch(keys, ivec2(i, 0), 0);
}

// (leader, main, branches) at t: linear between keyframes, 0 outside them.
vec3 channels(float t) {
	if (key_count < 1 || t < key_at(0).x || t > key_at(key_count - 1).x) {
		return vec3(0.0);
	}
	int lo = 0;
	int hi = key_count - 1;
	for (int k = 0; k < 24; k++) {  // bisection: 2^24 keyframes at most
		if (hi - lo <= 1) {
			break;
		}
		int mid = (lo + hi) / 2;
		if (key_at(mid).x <= t) {
			lo = mid;
		} else {
			hi = mid;
		}
	}
	vec4 a = key_at(lo);
	vec4 b = key_at(hi);
	return mix(a.yzw, b.yzw, clamp((t - a.x) / max(b.x - a.x, 1e-30), 0.0, 1.0));
}

void vertex() {
	float b = COLOR.r;
	if (timed) {
		float leader = UV2.x;
		float delay = UV2.y;
		if (leader > connect || time < leader) {
			b = 0.0;
		} else if (time < connect + delay) {
			b *= channels(time).x;
		} else {
			vec3 c = channels(time - delay);
			b *= main_channel ? c.y : c.z;
		}
	}
	brightness = b;
}

void fragment() {
	// The channel's cross-section: 1 over the middle third, smoothstep to 0 at the edges (the
	// profile the GLB embeds, server/api/bolt_glb.cpp).
	float x = clamp(3.0 * (1.0 - abs(2.0 * UV.y - 1.0)), 0.0, 1.0);
	ALBEDO = color * (brightness * x * x * (3.0 - 2.0 * x));
}
