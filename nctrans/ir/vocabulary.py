"""The neutral vocabulary of ModeChange (group -> allowed values), cycle kinds and variable spaces.

Front ends map their codes onto these names through `rules/<dialect>.toml`; the interpreter and the
emitters know only these names. Adding a value here is how a new concept enters the IR.
"""

MODAL_GROUPS: dict[str, tuple[str, ...]] = {
    # motion: what a Motion statement does. "cycle" while a canned cycle mode is active is tracked
    # by the "cycle" group instead; "none" after ISO G80 on controllers that cancel motion (LinuxCNC).
    "motion": ("rapid", "linear", "arc_cw", "arc_ccw", "thread", "none",
               "arc_3point", "arc_tangent",                  # Sinumerik CIP (Motion.via) / CT
               "tap_rigid", "tap_rigid_retract",             # Sinumerik G331 / G332
               "tap_interp",                                 # Fagor G63
               "tap_return"),                                # LinuxCNC G33.1: in and back out: lead F/S, hand by S's sign
    "plane": ("XY", "ZX", "YZ"),
    "distance": ("absolute", "incremental"),
    "arc_distance": ("incremental", "absolute"),          # ISO G91.1 / G90.1
    # inch_geometry: lengths in inch, feeds in the basic system (mm) - Sinumerik G70; "inch" also
    # reads feeds in inch (ISO G20, Sinumerik G700)
    "units": ("mm", "inch", "inch_geometry"),
    "feed_mode": ("per_min", "per_rev", "inverse_time"),
    "cutter_comp": ("off", "left", "right"),
    "tool_length": ("off", "plus", "minus"),
    # work_offset values are ISO names: G53 (none), G54..G59, G54.1P1..G54.1P300 (extended)
    "work_offset": (),
    "path_mode": ("exact_stop", "continuous", "tapping", "corner_override"),
    "exact_stop_once": ("on",),                             # ISO G09: this block only
    "cycle": ("off", "drill", "drill_dwell", "peck", "chip_break", "tap", "tap_left",
              "bore_feed_out", "bore_stop_rapid_out", "bore_dwell_feed_out", "fine_bore",
              "back_bore", "bore_manual"),
    "cycle_retract": ("initial", "r_plane"),                # ISO G98 / G99
    "spindle": ("cw", "ccw", "off", "orient"),
    "spindle_mode": ("rpm", "css"),                         # G97 / G96
    "coolant": ("mist", "flood", "off", "through"),
    "polar": ("off", "on"),                                 # ISO G15/G16
    "diameter": ("radius", "diameter"),                     # lathe DIAMOF/DIAMON
    "corner": ("arc", "intersection"),                      # Sinumerik G450 / G451
}

# Cycle-parameter keys used in CycleParams / CycleCall (neutral, all lengths in program units).
CYCLE_PARAMS = ("bottom", "r_plane", "retract_plane", "safety", "peck", "dwell", "shift",
                "repeat", "feed", "depth_rel", "first_peck", "decrement", "min_peck", "relief",
                # Sinumerik CYCLE800 swivel plane (rules/cycles.toml [[swivel]])
                "swivel_retract", "swivel_record", "swivel_state", "swivel_mode",
                "ref_x", "ref_y", "ref_z", "angle_1", "angle_2", "angle_3",
                "shift_x", "shift_y", "shift_z", "swivel_dir", "retract_inc")

# Neutral meanings of system variables. Each rules table maps its own spellings onto them in its
# [system_variables] section (`#5001`, `$AA_IW`, ...); the interpreter provides the values by meaning.
# A per-axis meaning is written "<meaning>.<axis>" for one axis (ISO #5001 = axis_position_work.X) or
# alone for a variable indexed by an axis (Sinumerik $AA_IW[X]).
SYSTEM_VARIABLES = (
    "axis_position_work",        # current position of an axis in work coordinates (program units)
    "axis_position_machine",     # the same in machine coordinates
    "programmable_frame",        # the programmable frame as a FRAME value (writable)
    "active_tool",               # number of the active tool
    "active_tool_edge",          # active tool offset (edge / D number)
    "feed",                      # programmed feed rate
    "spindle_speed",             # programmed spindle speed
    "spindle_direction",         # direction of the spindle: 3 clockwise, 4 counterclockwise, 5 stopped
    "active_tool_radius",        # radius of the active tool edge (with its wear; 0: none active)
    "plane_axis_1",              # geometry axes of the active plane, as axis names: abscissa,
    "plane_axis_2",              # ordinate,
    "plane_axis_3",              # applicate (the tool axis)
    "programmed_tool",           # the last programmed T number (selected, not yet changed in)
    "probe_position_work",       # where the last probing (skip / measuring) move stopped, per axis,
    "probe_position_machine",    # in work / machine coordinates: not modelled (reads are unknown)
    "parts_machined",            # workpiece counters of the control: machine state the analysis
    "parts_required",            # cannot know (reads are unknown)
    "argument_programmed",       # indexed by parameter position: whether the call of the running
                                 # procedure wrote that parameter (TRUE) or left it out (FALSE)
    "settable_frame_data",       # indexed [n] or [n, axis, component]: the settable frame n (work
                                 # offset G54.. and its rotation, scale, mirror), active at its selection
    "settable_frame",            # the active settable frame (writable: acts at once)
    "settable_frame_number",     # index of the active settable frame (0: none)
    "edge_length",               # indexed [tool, edge]: cutting-edge data the D number applies:
    "edge_radius",               # length along the tool axis, radius,
    "edge_length_wear",          # and their wear (added)
    "edge_radius_wear",
    "block_search_active",       # how the program runs: block search, simulation, dry run; the
    "simulation_active",         # analysis is a normal run from the start, so each reads FALSE
    "dry_run_active",
)
AXIS_MEANINGS = ("axis_position_work", "axis_position_machine", "probe_position_work",
                 "probe_position_machine")

# Variable spaces of nodes.Var
# "local": a local parameter of the call frame that exists once assigned (Fagor P0..P99, V.P.):
# reading it before is an error (NC101), not a vacant value
VAR_SPACES = ("num", "R", "name", "system", "arg", "local")

# CycleCall kinds beyond the "cycle" modal values: hole patterns that run the modal cycle at each
# position (Sinumerik HOLES1/HOLES2, parameters in rules/cycles.toml [[pattern]]).
CYCLE_CALL_KINDS = MODAL_GROUPS["cycle"] + ("holes_line", "holes_circle", "holes_grid",
                                             "swivel_plane", "milling")

# Passthrough reasons for constructs known to have no effect on the programmed path (front ends
# give these; nctrans.interp.unmodelled and --flatten pass over them without a warning). A reason
# starting with NO_EFFECT_PREFIX is such a construct too; one starting with MILL_ONLY only on a mill.
NO_MOTION_EFFECT = frozenset((
    "ISO dialect mode", "native dialect mode", "directive", "preprocessing stop", "data attribute",
    "macro definition", "declaration", "feedforward", "program attribute",
))
NO_EFFECT_PREFIX = "no motion effect"
MILL_ONLY = "no motion effect on a mill"
# Of those, the reasons whose construct does nothing another control would miss when it is written
# there as a comment (a declaration, an attribute, the source's own dialect switch, a preprocessing
# stop: the target reads its program its own way). Every other construct with no motion effect has
# an effect on its own control (an acceleration profile, single-block suppression, a workpiece
# counter, machine data) that a comment does not do: NC413. Words of a source's rules table
# `[options.no_motion_effect] harmless_elsewhere` are of the first kind too.
NO_EFFECT_ELSEWHERE = frozenset((
    "ISO dialect mode", "native dialect mode", "preprocessing stop", "data attribute",
    "macro definition", "declaration", "program attribute",
))

# Passthrough reasons of constructs that switch travel limits the interpreter does not model
# (Sinumerik NPROT/CPROT protection zones): besides NC220, the toolpath gets a `limits` record with
# zone "unmodelled", so the machine check says at that line that it cannot judge them (NC307).
UNMODELLED_LIMITS = frozenset(("protection zone",))

# Modal values the interpreter records but does not model: selecting one is reported (NC220) with
# what it leaves out. A value leaves this table when the interpreter models it: diameter programming
# and constant surface speed are modelled by nctrans.interp.lathe (CSS on a lathe or in diameter mode;
# on a mill it reports NC220 itself).
UNMODELLED_MODES: dict[tuple[str, str], str] = {
}
