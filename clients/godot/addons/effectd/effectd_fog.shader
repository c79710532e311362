// A fog table from /v1/fog applied to everything already drawn: a full-screen pass that reads
// each pixel's depth, turns it into the distance d and the world direction of the ray, looks the
// table up there, and writes colour * f + S (RGB = S, the fog's colour reaching the eye; A = f,
// the transmittance), as effectd's renderer and clients/three/effectd-three.js do. Pixels at
// the far plane (the sky) are left as they are. EffectdClient.fog_overlay() makes the quad and
// sets the uniforms from a table.
//
// The table's axes (docs/using/fog.md): u = distance over range; v = the ray's direction y over
// [-1, 1] when the table has elevations. A warped HEIGHT table (layout "warped", fog_warp.x > 0)
// has the axes of that page's section 4. The table is for a camera at table.cameraHeight: ask
// for a new one when the camera's height changes by more than the page says.
shader_type spatial;
render_mode unshaded, cull_disabled, depth_test_disable, depth_draw_never, shadows_disabled;

uniform sampler2D fog_table;        // size x elevations texels, filtered, clamped
uniform vec2 fog_range = vec2(0.0, 100.0);
uniform vec2 fog_texels = vec2(2.0, 1.0);
uniform float fog_cutoff = 1e30;    // table.cutoffDistance: no fog from there on
uniform vec4 fog_warp = vec4(0.0);  // warped: (k, falloff, kappa, lambda); k = 0 marks a linear table
uniform vec2 fog_warp_range = vec2(0.0, 1.0);  // warped: (factorStart, end)

void vertex() {
	POSITION = vec4(VERTEX.xy, 0.0, 1.0);  // a QuadMesh of size 2 x 2 covers the screen
}

vec2 fog_uv(float d, float y) {
	if (fog_warp.x == 0.0) {
		return vec2(clamp((min(d, fog_range.y) - fog_range.x) / (fog_range.y - fog_range.x), 0.0, 1.0),
		            fog_texels.y > 1.0 ? (y + 1.0) * 0.5 : 0.5);
	}
	float start = fog_warp_range.x;
	float span = fog_warp_range.y - start;
	if (y < 0.0 && fog_warp.z > 0.0) {  // a downward row's columns end where its fog is complete
		float K = fog_warp.z * exp(fog_warp.y * y * start);
		float x = -K * y;
		float own = fog_warp.w * K * (x > 1e-4 ? log(1.0 + x) / x : 1.0 - 0.5 * x);
		float lo = min(span, own);
		float hi = max(span, own);
		span = hi > 0.0 ? lo * pow(1.0 + pow(lo / hi, 8.0), -0.125) : 0.0;
	}
	return vec2(span > 0.0 ? clamp((d - start) / span, 0.0, 1.0) : 1.0,
	            0.5 + asinh(fog_warp.x * y) / (2.0 * asinh(fog_warp.x)));
}

void fragment() {
	vec3 behind = textureLod(SCREEN_TEXTURE, SCREEN_UV, 0.0).rgb;
	float depth = textureLod(DEPTH_TEXTURE, SCREEN_UV, 0.0).r;
	ALBEDO = behind;
	if (depth < 1.0) {
		vec4 at = INV_PROJECTION_MATRIX * vec4(vec3(SCREEN_UV, depth) * 2.0 - 1.0, 1.0);
		vec3 ray = at.xyz / at.w;  // view space
		float d = length(ray);
		if (d < fog_cutoff) {
			float y = clamp((CAMERA_MATRIX * vec4(ray / max(d, 1e-6), 0.0)).y, -1.0, 1.0);
			vec4 fog = texture(fog_table, (fog_uv(d, y) * (fog_texels - 1.0) + 0.5) / fog_texels);
			ALBEDO = behind * fog.a + fog.rgb;
		}
	}
}
