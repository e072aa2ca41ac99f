# Renders one frame of the lens's flare and exits (docs/exports.md):
#   godot3 --path DIR -- --light X,Y[,R,G,B] [--light ...] --size WxH --exposure EV --output FRAME.png
#        [--ghost-model gaussian|cos2] [--ghosts-out GHOSTS.json]
# as `fourierflare render --mode fitted --light X,Y --size WxH --preview FRAME.png --exposure EV`.
# --ghosts-out writes the ghosts drawn: [x, y, [flux R, G, B], [width along x], [along y]] in pixels.
# Without --output it shows the flare in a window instead (the editor's Play), of a light at the
# mouse unless --light is given, at --exposure (default 20 EV).
extends Node

const LensFlare = preload("res://addons/fourierflare/lens_flare.gd")

var window_flare = null # the flare shown in a window, following the mouse


# A path as given on the command line: relative to the shell's folder ($PWD), not to the project
# folder Godot runs in.
func from_shell(path):
	if path == "" or path.is_abs_path() or OS.get_environment("PWD") == "":
		return path
	return OS.get_environment("PWD").plus_file(path)


func fail(message):
	printerr("flare_frame: " + message)
	get_tree().quit(2)


func _ready():
	var lights = []
	var size = Vector2(1280, 720)
	var exposure = null
	var output = ""
	var ghosts_out = ""
	var model = "gaussian"
	var args = OS.get_cmdline_args()
	var i = 0
	while i < args.size():
		var a = args[i]
		var value = args[i + 1] if i + 1 < args.size() else ""
		if a == "--light":
			var v = value.split_floats(",")
			if v.size() != 2 and v.size() != 5:
				return fail("--light X,Y[,R,G,B], got '" + value + "'")
			var flux = Vector3(1, 1, 1) if v.size() == 2 else Vector3(v[2], v[3], v[4])
			lights.append([Vector2(v[0], v[1]), flux])
		elif a == "--size":
			var v = value.split("x")
			if v.size() != 2 or not v[0].is_valid_integer() or not v[1].is_valid_integer():
				return fail("--size WIDTHxHEIGHT, got '" + value + "'")
			size = Vector2(int(v[0]), int(v[1]))
		elif a == "--exposure":
			if not value.is_valid_float():
				return fail("--exposure EV, got '" + value + "'")
			exposure = float(value)
		elif a == "--output":
			output = from_shell(value)
		elif a == "--ghost-model":
			if value != "gaussian" and value != "cos2":
				return fail("--ghost-model gaussian or cos2, got '" + value + "'")
			model = value
		elif a == "--ghosts-out":
			ghosts_out = from_shell(value)
		else:
			i += 1
			continue
		i += 2
	var flare = LensFlare.new()
	flare.ghost_model = model
	flare.exposure = exposure if exposure != null else (20.0 if output == "" else 0.0)
	flare.rect_size = size
	flare.lights = lights
	if output == "":
		# In a window (the editor's Play): the flare over the window, for its size.
		flare.rect_size = OS.window_size
		add_child(flare)
		if lights.empty():
			window_flare = flare
		return
	# The frame is drawn into a viewport of exactly its size: no stretching, no engine post-processing.
	var viewport = Viewport.new()
	viewport.size = size
	viewport.usage = Viewport.USAGE_2D
	viewport.hdr = false
	viewport.disable_3d = true
	viewport.render_target_update_mode = Viewport.UPDATE_ALWAYS
	add_child(viewport)
	viewport.add_child(flare)
	if flare.table == null:
		return fail("no ghost table")
	if ghosts_out != "":
		var f = File.new()
		if f.open(ghosts_out, File.WRITE) != OK:
			return fail("cannot write " + ghosts_out)
		f.store_string(JSON.print(flare.instances()))
		f.close()
	yield(get_tree(), "idle_frame")
	yield(get_tree(), "idle_frame")
	yield(VisualServer, "frame_post_draw")
	var image = viewport.get_texture().get_data()
	image.flip_y() # OpenGL's rows run bottom to top
	image.convert(Image.FORMAT_RGB8)
	if image.save_png(output) != OK:
		return fail("cannot write " + output)
	get_tree().quit(0)


func _input(event):
	if window_flare != null and event is InputEventMouseMotion:
		window_flare.set_lights([[event.position, Vector3(1, 1, 1)]])
