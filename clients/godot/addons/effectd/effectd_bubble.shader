// The soap film of /v1/bubble's default shading (docs/effects.md §3.4), as effectd's own
// film shader draws it (effects/bubble/shader.cpp, shader.language glsl-es-300): the film's
// reflectance R from the thin-film table at its thickness and the view angle; each side drawn
// twice, what passes (pass 0: multiplied into what lies behind, 1 - R) and what it reflects
// (pass 1: added, R times the sky and the lights' lobes in the mirror direction). The far side
// first, then the near side. EffectdClient.bubble() makes the four materials from this one by
// swapping the render_mode line (blend_mul for pass 0; cull_front for the far side) and sets
// the uniforms from the answer; EffectdClient.bubble_update() sets a later time's.
//
// Mesh (EffectdClient.bubble_mesh, asked with uvOrigin "top-left"): positions, normals, UVs.
// Godot 3 has no uniform arrays: up to 4 lights, in light0 ... light3.
shader_type spatial;
render_mode unshaded, blend_add, cull_back, depth_draw_never, shadows_disabled;

uniform int film_pass = 1;                        // 0: transmittance (blend_mul), 1: reflection (blend_add)
uniform sampler2D thin_film;                 // thinFilm: u = thickness over thickness_range, v = cos(theta)
uniform vec2 thickness_range = vec2(0.0, 1000.0);  // nm at the table's first and last column
uniform bool use_thickness_field = false;
uniform sampler2D thickness_field;           // thickness (nm) over the mesh's UVs, repeat in u
uniform float thickness_nm = 500.0;          // without the field: one thickness for the film
uniform bool use_environment = false;
uniform samplerCube environment;             // the sky the film mirrors (world directions)
uniform vec3 sky_color = vec3(0.5);          // without an environment: a sky of one colour
uniform int light_count = 0;
uniform vec3 light0_direction; uniform vec3 light0_radiance; uniform float light0_sharpness = 1.0;
uniform vec3 light1_direction; uniform vec3 light1_radiance; uniform float light1_sharpness = 1.0;
uniform vec3 light2_direction; uniform vec3 light2_radiance; uniform float light2_sharpness = 1.0;
uniform vec3 light3_direction; uniform vec3 light3_radiance; uniform float light3_sharpness = 1.0;
uniform float wobble_phase = 0.0;            // eqn 11, reduced on the server
uniform float wobble_amplitude = 0.0;
uniform float wobble_frequency = 0.0;

void vertex() {
	// eqn 11; the normal by the inverse transpose of the wobble's diagonal Jacobian
	vec3 arg = vec3(wobble_phase) + wobble_frequency * VERTEX;
	VERTEX += wobble_amplitude * vec3(sin(arg.x), cos(arg.y), sin(arg.z));
	NORMAL /= 1.0 + wobble_amplitude * wobble_frequency * vec3(cos(arg.x), -sin(arg.y), cos(arg.z));
}

vec3 lobe(vec3 r, vec3 direction, vec3 radiance, float sharpness) {
	return radiance * pow(max(dot(r, direction), 0.0), sharpness);
}

void fragment() {
	// NORMAL and VIEW are in view space; cos(theta) and the mirror direction do not depend on
	// which way the normal faces, so the far side needs no flip.
	vec3 N = normalize(NORMAL);
	float cos_theta = clamp(abs(dot(N, VIEW)), 0.0, 1.0);
	float thickness = use_thickness_field ? texture(thickness_field, UV).r : thickness_nm;
	float u = clamp((thickness - thickness_range.x) / max(thickness_range.y - thickness_range.x, 1e-6), 0.0, 1.0);
	vec2 size = vec2(textureSize(thin_film, 0));
	vec3 R = texture(thin_film, (vec2(u, cos_theta) * (size - 1.0) + 0.5) / size).rgb;  // texel centres hold the axes' ends
	vec3 r = normalize((CAMERA_MATRIX * vec4(reflect(-VIEW, N), 0.0)).xyz);  // world
	vec3 seen = use_environment ? texture(environment, r).rgb : sky_color;
	if (light_count > 0) seen += lobe(r, light0_direction, light0_radiance, light0_sharpness);
	if (light_count > 1) seen += lobe(r, light1_direction, light1_radiance, light1_sharpness);
	if (light_count > 2) seen += lobe(r, light2_direction, light2_radiance, light2_sharpness);
	if (light_count > 3) seen += lobe(r, light3_direction, light3_radiance, light3_sharpness);
	ALBEDO = film_pass == 0 ? vec3(1.0) - R : R * seen;
}
