# FourierFlare lens flare for Godot 3: a lens's ghost table (exported by `fourierflare export LENS
# --format godot`) drawn for lights at screen positions, as `fourierflare render --mode fitted`
# draws them (docs/exports.md). Put the node over the screen (a full-rect ColorRect) and call
# set_lights(); the flare is the image the CLI's preview shows at the node's exposure.
#
# Per light at pixel p: its distance r from the frame's centre on the sensor (mm: the frame spans
# the sensor's width) gives the field angle whose direct image lies at r; every ghost's entry at that
# angle (linear between the table's angles) sets its flux, its centre m r along p and its widths
# along p and across it, turned onto the screen's axes.
extends ColorRect

export(String, FILE, "*.json") var table_path = "res://addons/fourierflare/ghost_table.json"
export(String, "gaussian", "cos2") var ghost_model = "gaussian"
export(float) var exposure = 0.0        # EV: the flux is scaled by 2^exposure before tonemapping
export(float) var sensor_width_mm = 0.0 # the width the frame spans; 0: the table's sensor

var table = null
var lights = [] # each [Vector2 position in pixels, Vector3 flux R, G, B]


func _ready():
	if table == null:
		table = load_table(table_path)
	var m = ShaderMaterial.new()
	m.shader = load("res://addons/fourierflare/lens_flare.shader")
	material = m
	update_ghosts()


static func load_table(path):
	var f = File.new()
	if f.open(path, File.READ) != OK:
		push_error("FourierFlare: cannot read " + path)
		return null
	var parsed = JSON.parse(f.get_as_text())
	f.close()
	if parsed.error != OK or typeof(parsed.result) != TYPE_DICTIONARY or parsed.result.get("schema") != "fourierflare.ghost-table":
		push_error("FourierFlare: " + path + " is not a FourierFlare ghost table")
		return null
	return parsed.result


# lights: an array of [Vector2 pixels (origin top-left, y down), Vector3 RGB flux].
func set_lights(new_lights):
	lights = new_lights
	update_ghosts()


# (index, fraction) of a between sorted angles, clamped to them.
static func locate(angles, a):
	var n = angles.size()
	if n < 2 or a <= angles[0]:
		return [0, 0.0]
	if a >= angles[n - 1]:
		return [n - 2, 1.0]
	var i = angles.bsearch(a, false) - 1
	return [i, (a - angles[i]) / (angles[i + 1] - angles[i])]


func direct_at(w, a):
	var angles = table["field_angles_deg"]
	var d = table["direct_image_height_mm"][w]
	if angles.size() < 2:
		return d[0]
	var l = locate(angles, a)
	return d[l[0]] + (d[l[0] + 1] - d[l[0]]) * l[1]


# A ghost's entry at angle a: flux, centroid and profile widths (mm), linear between its angles;
# where it is dark at one end, the lit end's shape with its flux faded.
func entry(g, w, a):
	var ghost = table["ghosts"][g]
	var row = ghost["wavelengths"][w]
	var fit = row[ghost_model]
	var kr = "sigma_radial_mm" if ghost_model == "gaussian" else "w_radial_mm"
	var kt = "sigma_tangential_mm" if ghost_model == "gaussian" else "w_tangential_mm"
	var angles = ghost["field_angles_deg"]
	if angles.size() < 2:
		return [row["relative_flux"][0], row["centroid_mm"][0], fit[kr][0], fit[kt][0]]
	var l = locate(angles, a)
	var i = l[0]
	var t = l[1]
	var fa = row["relative_flux"][i]
	var fb = row["relative_flux"][i + 1]
	if (fa <= 0.0) != (fb <= 0.0):
		var j = i + 1 if fa <= 0.0 else i
		var fade = t if fa <= 0.0 else 1.0 - t
		return [row["relative_flux"][j] * fade, row["centroid_mm"][j], fit[kr][j], fit[kt][j]]
	var out = []
	for v in [row["relative_flux"], row["centroid_mm"], fit[kr], fit[kt]]:
		out.append(v[i] + (v[i + 1] - v[i]) * t)
	return out


func nearest_wavelength(nm):
	var wl = table["wavelengths_nm"]
	var best = 0
	for w in range(1, wl.size()):
		if abs(wl[w] - nm) < abs(wl[best] - nm):
			best = w
	return best


# The field angle whose direct image (green) lies r mm from the centre; the largest beyond it.
func field_angle(r):
	var g = nearest_wavelength(550.0)
	var angles = table["field_angles_deg"]
	var lo = angles[0]
	var hi = angles[angles.size() - 1]
	if r >= direct_at(g, hi):
		return hi
	for _k in range(60):
		var mid = 0.5 * (lo + hi)
		if direct_at(g, mid) < r:
			lo = mid
		else:
			hi = mid
	return 0.5 * (lo + hi)


func magnification(g, w, a):
	var own = table["ghosts"][g]["field_angles_deg"]
	var angle = max(a, own[1]) if own.size() > 1 and a < own[1] else a
	var d = direct_at(w, angle)
	return entry(g, w, angle)[1] / d if d != 0.0 else 0.0


# The ghosts of every light: [x, y, flux RGB, widths along x RGB, along y RGB] in pixels.
func instances():
	var out = []
	if table == null:
		return out
	var size_px = rect_size
	var sensor = sensor_width_mm if sensor_width_mm > 0.0 else float(table["sensor"]["width_mm"])
	var pitch = sensor / size_px.x
	var ch = [nearest_wavelength(650.0), nearest_wavelength(550.0), nearest_wavelength(450.0)]
	for light in lights:
		var pos = light[0]
		var flux = light[1]
		var sx = (pos.x - 0.5 * size_px.x) * pitch
		var sy = (0.5 * size_px.y - pos.y) * pitch
		var r = sqrt(sx * sx + sy * sy)
		var ex = sx / r if r > 0.0 else 0.0
		var ey = sy / r if r > 0.0 else 1.0
		var angle = field_angle(r)
		var ra = atan2(-ey, ex)
		var c = cos(ra)
		var s = sin(ra)
		for g in range(table["ghosts"].size()):
			var fl = []
			var wx = []
			var wy = []
			var lit = false
			var usable = true
			for k in range(3):
				var e = entry(g, ch[k], angle)
				fl.append(flux[k] * e[0])
				lit = lit or fl[k] > 0.0
				var wr = e[2] / pitch
				var wt = e[3] / pitch
				wx.append(sqrt(wr * wr * c * c + wt * wt * s * s))
				wy.append(sqrt(wr * wr * s * s + wt * wt * c * c))
				usable = usable and wx[k] > 0.0 and wy[k] > 0.0
			if not lit or not usable:
				continue
			var m = magnification(g, ch[1], angle)
			out.append([0.5 * size_px.x + m * r * ex / pitch, 0.5 * size_px.y - m * r * ey / pitch, fl, wx, wy])
	return out


func update_ghosts():
	if material == null:
		return
	var ghosts = instances()
	var image = Image.new()
	image.create(3, max(1, ghosts.size()), false, Image.FORMAT_RGBAF)
	image.lock()
	for i in range(ghosts.size()):
		var k = ghosts[i]
		image.set_pixel(0, i, Color(k[0], k[1], k[2][0], k[2][1]))
		image.set_pixel(1, i, Color(k[2][2], k[3][0], k[3][1], k[3][2]))
		image.set_pixel(2, i, Color(k[4][0], k[4][1], k[4][2], 0.0))
	image.unlock()
	var texture = ImageTexture.new()
	texture.create_from_image(image, 0) # no filtering, no mipmaps, no repeat: texels read exactly
	material.set_shader_param("ghosts", texture)
	material.set_shader_param("ghost_count", ghosts.size())
	material.set_shader_param("frame_size", rect_size)
	material.set_shader_param("exposure_scale", pow(2.0, exposure))
	material.set_shader_param("cos2", ghost_model == "cos2")
