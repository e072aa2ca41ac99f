// FourierFlare: the ghosts of a lens drawn as `fourierflare render --mode fitted --preview` draws
// them. Each ghost is a separable profile on the screen's axes (Gaussian of sigma w, or cos^2 of
// half-width w), its flux integrated exactly over every pixel of its footprint, the sum tonemapped
// as the CLI's preview: v = flux * 2^EV, v / (1 + v), the sRGB transfer function.
// The ghosts come from lens_flare.gd: texture row i holds ghost i in three texels,
//   (x px, y px, flux R, flux G), (flux B, wx R, wx G, wx B), (wy R, wy G, wy B, unused);
// pixels are counted from the top-left corner, pixel (i, j) covering [i, i + 1] x [j, j + 1].
shader_type canvas_item;
render_mode blend_disabled;

uniform sampler2D ghosts;
uniform int ghost_count = 0;
uniform vec2 frame_size = vec2(1.0);
uniform float exposure_scale = 1.0;
uniform bool cos2 = false;

// erf to 1.5e-7 (Abramowitz and Stegun 7.1.26).
float erf_as(float x) {
	float s = sign(x);
	float a = abs(x);
	float t = 1.0 / (1.0 + 0.3275911 * a);
	float y = 1.0 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-a * a);
	return s * y;
}

// The share of a unit profile of width w centred at 0 that falls on [a, b].
float share(float a, float b, float w) {
	if (cos2) {
		float ca = clamp(a, -w, w);
		float cb = clamp(b, -w, w);
		// Int cos^2(pi u / 2w) du = u/2 + (w / 2 pi) sin(pi u / w), over the integral w.
		return (0.5 * (cb - ca) + w / 6.283185307 * (sin(3.141592654 * cb / w) - sin(3.141592654 * ca / w))) / w;
	}
	float k = 0.7071067812 / w;
	return 0.5 * (erf_as(b * k) - erf_as(a * k));
}

void fragment() {
	vec2 p = floor(UV * frame_size);
	float reach = cos2 ? 1.0 : 6.069380; // sqrt(2 ln 1e8): the profile at 1e-8 of its peak
	vec3 sum = vec3(0.0);
	for (int i = 0; i < ghost_count; i++) {
		vec4 t0 = texelFetch(ghosts, ivec2(0, i), 0);
		vec4 t1 = texelFetch(ghosts, ivec2(1, i), 0);
		vec4 t2 = texelFetch(ghosts, ivec2(2, i), 0);
		vec2 c = t0.xy;
		vec3 flux = vec3(t0.z, t0.w, t1.x);
		vec3 wx = t1.yzw;
		vec3 wy = t2.xyz;
		// The footprint: the pixels from floor(c - extent) to floor(c + extent), as the CLI's.
		vec2 ext = reach * vec2(max(wx.r, max(wx.g, wx.b)), max(wy.r, max(wy.g, wy.b)));
		if (any(lessThan(p, floor(c - ext))) || any(greaterThan(p, floor(c + ext))))
			continue;
		vec2 a = p - c;
		vec2 b = a + 1.0;
		sum += flux * vec3(share(a.x, b.x, wx.r) * share(a.y, b.y, wy.r), share(a.x, b.x, wx.g) * share(a.y, b.y, wy.g),
		                   share(a.x, b.x, wx.b) * share(a.y, b.y, wy.b));
	}
	vec3 v = max(sum * exposure_scale, vec3(0.0));
	vec3 t = v / (1.0 + v);
	vec3 lo = 12.92 * t;
	vec3 hi = 1.055 * pow(t, vec3(1.0 / 2.4)) - 0.055;
	COLOR = vec4(mix(lo, hi, step(vec3(0.0031308), t)), 1.0);
}
