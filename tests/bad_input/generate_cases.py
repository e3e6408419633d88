#!/usr/bin/env python3
"""Generates cases.txt, the bad-input catalogue (tests/CMakeLists.txt runs each
line as a ctest). Kept for review and regeneration; CI needs only cases.txt.

`vdyn check` lists every error it finds (one per line; a bad plugin also makes
its outputs unknown), so its cases assert that one line holds the text; every
other program must print exactly one line.

Line format (fields separated by ' | '):
  name | exit code | expected text (fixed string) | data file (JSON text or -) | program and arguments
In the command, {CASE} is the data file written for the case, {OUT} a fresh
output folder, {DATA} vehicles/data. Every study also gets --no-plots where it has it.
"""
import json
import re

cases = []


def add(name, rc, text, data, cmd):
    assert ' | ' not in text and '\n' not in (data or '')
    cases.append((name, rc, text, data if data is not None else '-', cmd))


def variant(base, patch):
    d = {"based_on": base}
    d.update(patch)
    return json.dumps(d)


def nested(path, value):
    keys = path.split('.')
    d = value
    for k in reversed(keys):
        d = {k: d}
    return d


QC = 'quarter_car --no-plots --out {OUT} --data {CASE} --t-end-s 0.01'
CH3 = 'ch3_transient --no-plots --out {OUT} --data {CASE} --t-end-s 0.01'
CH3V = 'ch3_transient --no-plots --out {OUT} --t-end-s 0.01'

# --- data-file keys: quarter_car.json --------------------------------------------------------------
qc_numbers = [
    # key path, typo, negative text, zero text, huge value, huge text
    ('chassis_mass_kg', 'chasis_mass_kg', 'chassis_mass_kg must be positive', 'chassis_mass_kg must be positive', None, None),
    ('gravity_m_per_s2', 'gravity', 'gravity_m_per_s2 must not be negative', None, None, None),
    ('upper_pivot_offset_m', 'upper_pivot_ofset_m', None, None, None, None),
    ('road.amplitude_m', 'road.amplitud_m', None, None, None, None),
    ('road.frequency_Hz', 'road.frequency_hz', None, None, None, None),
    ('corner_overrides.spring.stiffness_N_per_m', 'corner_overrides.spring.stifness_N_per_m',
     'corner_overrides.spring.stiffness_N_per_m must be positive', 'corner_overrides.spring.stiffness_N_per_m must be positive', None, None),
    ('corner_overrides.spring.damping_N_s_per_m', 'corner_overrides.spring.dampin_N_s_per_m',
     'corner_overrides.spring.damping_N_s_per_m must not be negative', None, None, None),
    ('corner_overrides.bodies.knuckle.mass_kg', 'corner_overrides.bodies.knuckle.mass_g',
     'knuckle.mass_kg must be positive', 'knuckle.mass_kg must be positive', None, None),
    ('tire.params.radial_stiffness_N_per_m', 'tire.params.radial_stifness_N_per_m',
     'tire.params.radial_stiffness_N_per_m must be positive', 'tire.params.radial_stiffness_N_per_m must be positive', None, None),
    ('tire.params.unloaded_radius_m', 'tire.params.unloaded_radius', 'unloaded_radius_m must be positive',
     'unloaded_radius_m must be positive', 3.0, 'unloaded_radius_m must lie in (0, 1.5] m, got 3'),
]
for key, typo, neg, zero, huge, hugetext in qc_numbers:
    leaf = key.split('.')[-1]
    tag = key.replace('.', '_')
    add(f'QC.{tag}.WrongType', 1, f'{key}: expected a number, got string', variant('quarter_car.json', nested(key, 'abc')), QC)
    add(f'QC.{tag}.Array', 1, f'{key}: expected a number, got array', variant('quarter_car.json', nested(key, [1])), QC)
    add(f'QC.{tag}.Inf', 1, 'number out of range', variant('quarter_car.json', nested(key, 0)).replace(': 0}', ': 1e999}'), QC)
    add(f'QC.{tag}.NaN', 1, 'is not valid JSON', variant('quarter_car.json', nested(key, 0)).replace(': 0}', ': NaN}'), QC)
    parts = key.split('.')
    typo_leaf = typo.split('.')[-1]
    add(f'QC.{tag}.Misspelled', 1, f"{typo}: unknown key (did you mean '{leaf}'?)",
        variant('quarter_car.json', nested(typo, 1.0)), QC)
    unknown = '.'.join(parts[:-1] + ['extra_value_m']) if len(parts) > 1 else 'extra_value_m'
    add(f'QC.{tag}.Unknown', 1, f'{unknown}: unknown key', variant('quarter_car.json', nested(unknown, 1.0)), QC)
    if neg:
        add(f'QC.{tag}.Negative', 1, neg, variant('quarter_car.json', nested(key, -1.0)), QC)
    if zero:
        add(f'QC.{tag}.Zero', 1, zero, variant('quarter_car.json', nested(key, 0.0)), QC)
    if huge is not None:
        add(f'QC.{tag}.OutOfRange', 1, hugetext, variant('quarter_car.json', nested(key, huge)), QC)

# missing required keys: a variant with the key deleted (merge patch: null)
for key, text in [('chassis_mass_kg', 'chassis_mass_kg: missing key'),
                  ('road', 'road: missing key'), ('road.type', 'road.type: missing key'),
                  ('vehicle_data', 'vehicle_data: missing key')]:  # (corner: default front_right)
    add(f'QC.Missing.{key.replace(".", "_")}', 1, text, variant('quarter_car.json', nested(key, None)), QC)
# other quarter-car keys
add('QC.RoadType.Unknown', 1, "road.type: unknown road type 'bumpy'; known: flat, sine",
    variant('quarter_car.json', {"road": {"type": "bumpy"}}), QC)
add('QC.SteerLock.WrongType', 1, 'steer_lock: expected true or false, got "yes"',
    variant('quarter_car.json', {"steer_lock": "yes"}), QC)
add('QC.Corner.Unknown', 1, "front_left: missing key", variant('quarter_car.json', {"corner": "front_left"}), QC)
add('QC.VehicleData.Missing', 1, "data file 'nope.json' not found", variant('quarter_car.json', {"vehicle_data": "nope.json"}), QC)
add('QC.ExtraPlugins.Unknown', 1, 'extra_plugins: unknown key', variant('quarter_car.json', {"extra_plugins": ["x"]}), QC)
add('QC.Simulation.Unknown', 1, 'simulation: unknown key', variant('quarter_car.json', {"simulation": {"t_end_s": 1}}), QC)
add('QC.Gravity.Unknown', 1, "gravity: unknown key (did you mean 'gravity_m_per_s2'?)", variant('quarter_car.json', {"gravity": 3}), QC)
add('QC.WheelSpinAxes.Unknown', 1, "corner_overrides.joints.wheel_spin_axes: unknown key (did you mean 'wheel_spin_axis'?)",
    variant('quarter_car.json', {"corner_overrides": {"joints": {"wheel_spin_axes": [0, 1, 0]}}}), QC)
add('QC.WheelSpinAxis.WrongSize', 1, 'wheel_spin_axis: expected 3 numbers [x, y, z], got 2',
    variant('quarter_car.json', {"corner_overrides": {"joints": {"wheel_spin_axis": [0, 1]}}}), QC)
add('QC.Inertia.Triangle', 1, 'violates the triangle inequality',
    variant('quarter_car.json', {"corner_overrides": {"bodies": {"wheel": {"inertia_kg_m2": [1, 1, 5]}}}}), QC)
add('QC.TireParams.Unknown', 1, "tire.params.mu: unknown key (did you mean 'mu_max'?)",
    variant('quarter_car.json', {"tire": {"params": {"mu": 1}}}), QC)
add('QC.TirePlugin.Unknown', 1, "unknown force element plugin 'pacejka'",
    variant('quarter_car.json', {"tire": {"plugin": "pacejka"}}), QC)
add('QC.MuOrder', 1, 'mu_min (2) must not exceed mu_max',
    variant('quarter_car.json', {"tire": {"params": {"mu_min": 2}}}), QC)
add('QC.DuplicateKey', 1, "duplicate key 'chassis_mass_kg'",
    '{"based_on": "quarter_car.json", "chassis_mass_kg": 100, "chassis_mass_kg": 200}', QC)

# --- files ---------------------------------------------------------------------------------------------
add('File.Missing', 1, "data file 'nope.json' not found", None, 'quarter_car --no-plots --out {OUT} --data nope.json')
add('File.Empty', 1, 'is empty (expected a JSON object)', '', QC)
add('File.Whitespace', 1, 'is empty (expected a JSON object)', '   ', QC)
add('File.Array', 1, 'expected a JSON object at the top level, got array', '[1, 2, 3]', QC)
add('File.Number', 1, 'expected a JSON object at the top level, got number', '42', QC)
add('File.String', 1, 'expected a JSON object at the top level, got string', '"quarter_car"', QC)
add('File.Truncated', 1, 'is not valid JSON (line 1', '{"based_on": "quarter_car.json", "chassis_mass_kg": ', QC)
add('File.TrailingComma', 1, 'is not valid JSON', '{"based_on": "quarter_car.json",}', QC)
add('File.SingleQuotes', 1, 'is not valid JSON', "{'based_on': 'quarter_car.json'}", QC)
add('File.Garbage', 1, 'is not valid JSON', 'vdyn', QC)
add('File.BasedOnMissing', 1, "data file 'nowhere.json' not found", '{"based_on": "nowhere.json"}', QC)
add('File.BasedOnWrongType', 1, 'based_on: expected a data file name, got 3', '{"based_on": 3}', QC)
add('File.BasedOnSelf', 1, 'based_on: the variants form a cycle', '{"based_on": "case.json"}', QC)
add('File.Directory', 1, "is a folder, not a JSON file", None, 'quarter_car --no-plots --out {OUT} --data {DATA}')
add('File.BadComment', 1, 'is not valid JSON', '{"based_on": "quarter_car.json" /* unterminated', QC)
add('File.SceneMissing', 1, "data file 'nope.json' not found", None, 'ch3_transient --no-plots --out {OUT} --data nope.json')
add('File.SceneEmpty', 1, 'is empty (expected a JSON object)', '', 'ch3_transient --no-plots --out {OUT} --data {CASE}')
add('File.SceneArray', 1, 'expected a JSON object', '[1]', 'vdyn check {CASE}')
add('File.SceneInvalid', 1, 'is not valid JSON', '{"name": }', 'vdyn check {CASE}')

# --- scene keys (vdyn check / vdyn run --set: validation only, no simulation) ------------------------------
SC = '{DATA}/scenes/ch3_transient.json'
CHK = 'vdyn check ' + SC + ' --set '
for key, bad, text in [
        ('vehicle.initial_speed_m_s', '1000', 'vehicle.initial_speed_m_s must lie in [0, 100] m/s, got 1000'),
        ('vehicle.initial_speed_m_s', '-1', 'vehicle.initial_speed_m_s must lie in [0, 100] m/s, got -1'),
        ('vehicle.initial_speed_m_s', 'abc', 'vehicle.initial_speed_m_s: expected a number, got string'),
        ('vehicle.initial_speed_m_s', 'nan', "--set 'vehicle.initial_speed_m_s=nan': nan is not a finite number"),
        ('vehicle.initial_speed_m_s', 'inf', "--set 'vehicle.initial_speed_m_s=inf': inf is not a finite number"),
        ('vehicle.initial_speed_m_s', '1e999', 'number out of range (not a finite double): 1e999'),
        ('vehicle.type', 'truck', "unknown vehicle 'truck'"),
        ('vehicle.data', 'nope.json', "data file 'nope.json' not found"),
        ('vehicle.overrides.chassis.mass_kg', '-5', 'chassis.mass_kg must be positive, got -5'),
        ('vehicle.overrides.chassis.mass', '800', "vehicle.overrides.chassis.mass: unknown key (did you mean 'mass_kg'?)"),
        ('vehicle.overrides.gravity', '9.81', "vehicle.overrides.gravity: unknown key (did you mean 'gravity_m_per_s2'?)"),
        ('vehicle.overrides.axles.front.suspension.template', 'rigid', "axles.front.suspension.template: unknown suspension template 'rigid'; known: double_wishbone, double_wishbone_reduced"),
        ('vehicle.colour', 'red', 'vehicle.colour: unknown key'),
        ('plugins.speed_hold.speed_m_s', '1000', 'speed_m_s must lie in (0, 100] m/s, got 1000'),
        ('plugins.speed_hold.speed_m_s', '0', 'speed_m_s must be positive, got 0'),
        ('plugins.speed_hold.speed_m_s', '"fast"', 'speed_m_s: expected a number, got string'),
        ('plugins.speed_hold.speed_ms', '3', "speed_ms: unknown key (did you mean 'speed_m_s'?)"),
        ('plugins.speed_hold.attach', 'roof', "has no attachment 'roof'"),
        ('plugins.front_steer.command.final_rad', '1.5', 'steering final_rad must lie in [-1.2, 1.2], got 1.5'),
        ('plugins.front_steer.command.final_rad', '1', 'command.final_rad must lie in [-0.785398, 0.785398] rad (+-45 deg), got 1'),
        ('plugins.front_steer.command.final_rad', 'nan', "--set 'plugins.front_steer.command.final_rad=nan': nan is not a finite number"),
        ('plugins.front_steer.command.type', 'wiggle', "unknown steering command 'wiggle'"),
        ('plugins.front_steer.command.duration', '1', "command.duration: unknown key (did you mean 'duration_s'?)"),
        ('plugins.rear_steer.command.final_rad', '-0.9', 'command.final_rad must lie in [-0.785398, 0.785398] rad (+-45 deg), got -0.9'),
        ('plugins.nosuch.x', '1', "has no element named 'nosuch'"),
        ('analysis.t_end', '5', "analysis.t_end: unknown key (did you mean 't_end_s'?)"),
        ('analysis.t_end_s', '-1', 'analysis.t_end_s must be positive, got -1'),
        ('analysis.t_end_s', '1e9', 'analysis.t_end_s must lie in (0, 1e5] s, got 1000000000'),
        ('analysis.t_end_s', 'abc', 'analysis.t_end_s: expected a number, got string'),
        ('analysis.t_end_s', '-inf', "--set 'analysis.t_end_s=-inf': -inf is not a finite number"),
        ('analysis.report_interval_s', '-0.1', 'analysis.report_interval_s must be >= 0 (0 = none), got -0.1'),
        ('analysis.report_interval_s', '50', 'analysis.report_interval_s (50 s) must not exceed'),
        ('analysis.report_interval_s', '1e-9', 'gives more than 1e6 samples'),
        ('analysis.integrator.method', 'euler', "unknown integrator 'euler'"),
        ('analysis.integrator.methd', 'rk3', "analysis.integrator.methd: unknown key (did you mean 'method'?)"),
        ('analysis.integrator.accuracy', '2', 'accuracy must lie in (0, 1), got 2'),
        ('analysis.integrator.accuracy', '0', 'accuracy must lie in (0, 1), got 0'),
        ('analysis.type', 'dance', "unknown analysis 'dance'"),
        ('outputs.0', 'chassis.colour', "the scene has no output 'chassis.colour'"),
        ('colour', 'red', 'colour: unknown key'),
]:
    tag = key.replace('.', '_') + '.' + re.sub(r'[^A-Za-z0-9]', '_', bad)
    add(f'Scene.{tag}', 1, text, None, CHK + key + '=' + bad)
# the same through `vdyn run`: a named error before any simulation
for key, bad, text in [
        ('analysis.t_end_s', 'nan', "--set 'analysis.t_end_s=nan': nan is not a finite number"),
        ('analysis.t_end', '5', "analysis.t_end: unknown key (did you mean 't_end_s'?)"),
        ('plugins.speed_hold.speed_m_s', '1000', 'speed_m_s must lie in (0, 100] m/s, got 1000'),
        ('vehicle.overrides.chassis.mass_kg', 'heavy', 'chassis.mass_kg: expected a number, got string'),
]:
    tag = key.replace('.', '_') + '.' + re.sub(r'[^A-Za-z0-9]', '_', bad)
    add(f'SceneRun.{tag}', 1, text, None, 'vdyn run ' + SC + ' --out {OUT} --set ' + key + '=' + bad)
add('Scene.SetNoValue', 1, "--set 'analysis.t_end_s': expected key.path=value", None, CHK + 'analysis.t_end_s')
add('Scene.SetEmptyKey', 1, 'empty part', None, CHK + 'analysis..t_end_s=1')
add('Scene.BasedOnCycle', 1, 'based_on', '{"based_on": "case.json"}', 'vdyn check {CASE}')
add('Scene.Positional', 1, "too many positional options", None, 'vdyn check ' + SC + ' stray')

# vehicle file (appendix_a.json) variants through ch3_transient: the scene with vehicle.data = the case
VEH = lambda patch: variant('appendix_a.json', patch)
for name, patch, text in [
        ('ChassisMass.Negative', {"chassis": {"mass_kg": -800}}, 'chassis.mass_kg must be positive, got -800'),
        ('ChassisMass.Zero', {"chassis": {"mass_kg": 0}}, 'chassis.mass_kg must be positive, got 0'),
        ('ChassisMass.Typo', {"chassis": {"mass": 800}}, "chassis.mass: unknown key (did you mean 'mass_kg'?)"),
        ('ChassisInertia.Short', {"chassis": {"inertia_kg_m2": [1, 2]}}, 'chassis.inertia_kg_m2: expected 3 numbers'),
        ('ChassisInertia.Negative', {"chassis": {"inertia_kg_m2": [250, -1000, 1100]}}, 'chassis.inertia_kg_m2[1] must be positive'),
        ('Gravity.Typo', {"gravity": 9.81}, "gravity: unknown key (did you mean 'gravity_m_per_s2'?)"),
        ('Gravity.Negative', {"gravity_m_per_s2": -9.81}, 'gravity_m_per_s2 must not be negative'),
        ('FrontSpring.Zero', {"axles": {"front": {"suspension": {"spring": {"stiffness_N_per_m": 0}}}}}, 'axles.front.suspension.spring.stiffness_N_per_m must be positive, got 0'),
        ('FrontSpring.Typo', {"axles": {"front": {"suspension": {"spring": {"stifness_N_per_m": 1}}}}}, "axles.front.suspension.spring.stifness_N_per_m: unknown key (did you mean 'stiffness_N_per_m'?)"),
        ('RearDamper.Negative', {"axles": {"rear": {"suspension": {"spring": {"damping_N_s_per_m": -1}}}}}, 'axles.rear.suspension.spring.damping_N_s_per_m must not be negative'),
        ('Joint.Typo', {"axles": {"front": {"suspension": {"joints": {"lower_pivot": {"parent_pont_m": [0, 0, 0]}}}}}}, "parent_pont_m: unknown key (did you mean 'parent_point_m'?)"),
        ('Joint.AxisDegenerate', {"axles": {"front": {"suspension": {"joints": {"lower_pivot": {"parent_axis_point_m": [1.310, -0.295, -0.385]}}}}}}, 'parent_axis_point_m coincides with parent_point_m'),
        ('WheelSpinAxes', {"axles": {"front": {"suspension": {"joints": {"wheel_spin_axes": [0, 1, 0]}}}}}, "wheel_spin_axes: unknown key (did you mean 'wheel_spin_axis'?)"),
        ('TireRadius.Huge', {"tire": {"params": {"unloaded_radius_m": 3.0}}}, 'tire.params.unloaded_radius_m must lie in (0, 1.5] m, got 3'),
        ('TireRadius.Negative', {"tire": {"params": {"unloaded_radius_m": -0.3}}}, 'unloaded_radius_m must be positive'),
        ('TireCarcass.TooLarge', {"tire": {"params": {"carcass_radius_m": 0.5}}}, 'carcass_radius_m must be smaller than unloaded_radius_m'),
        ('TireMu.Negative', {"tire": {"params": {"mu_max": -1}}}, 'mu_max must not be negative'),
        ('TireRelaxation.Negative', {"tire": {"params": {"relaxation_length_lateral_m": -0.5}}}, 'relaxation_length_lateral_m must not be negative'),
        ('TireUnknown', {"tire": {"params": {"pacejka_b": 10}}}, 'tire.params.pacejka_b: unknown key'),
        ('TirePlugin.Unknown', {"tire": {"plugin": "magic"}}, "unknown force element plugin 'magic'"),
        ('TopLevel.Unknown', {"wheelbase_m": 2.5}, 'wheelbase_m: unknown key'),
        ('Road.UnknownType', {"road": {"type": "gravel"}}, "road.type: unknown road type 'gravel'"),
        ('Road.UnknownKey', {"road": {"type": "flat", "heigth_m": 0}}, "road.heigth_m: unknown key (did you mean 'height_m'?)"),
        ('SuspensionTemplate.Unknown', {"axles": {"front": {"suspension": {"template": "rigid"}}}}, "axles.front.suspension.template: unknown suspension template 'rigid'; known: double_wishbone, double_wishbone_reduced"),
        ('Axle.UnknownKey', {"axles": {"front": {"steer": True}}}, 'axles.front.steer: unknown key'),
]:
    add(f'Ch3Vehicle.{name}', 1, text, VEH(patch), 'ch3_transient --no-plots --out {OUT} --t-end-s 0.01 --data {CH3CASE}')

# --- options ----------------------------------------------------------------------------------------
opt_cases = [
    ('SpeedNaN', '--speed-m-s nan', '--speed-m-s must be a finite number, got nan'),
    ('SpeedInf', '--speed-m-s inf', '--speed-m-s must be a finite number, got inf'),
    ('SpeedNegative', '--speed-m-s -10', '--speed-m-s must lie in [0.5, 100] m/s (a steady turn needs the tires rolling), got -10'),
    ('SpeedZero', '--speed-m-s 0', '--speed-m-s must lie in [0.5, 100] m/s (a steady turn needs the tires rolling), got 0'),
    ('SpeedCreep', '--speed-m-s 1e-6', '--speed-m-s must lie in [0.5, 100] m/s (a steady turn needs the tires rolling), got 1e-06'),
    ('SpeedHuge', '--speed-m-s 1000', '--speed-m-s must lie in [0.5, 100] m/s (a steady turn needs the tires rolling), got 1000'),
    ('SpeedText', '--speed-m-s fast', "the argument ('fast') for option '--speed-m-s' is invalid"),
    ('SpeedEmpty', '--speed-m-s', "the required argument for option '--speed-m-s' is missing"),
    ('FrontNaN', '--front-deg nan', '--front-deg must be a finite number, got nan'),
    ('FrontInf', '--front-deg -inf', '--front-deg must be a finite number, got -inf'),
    ('FrontHuge', '--front-deg 90', '--front-deg must lie in [-45, 45], got 90'),
    ('FrontHugeNegative', '--front-deg -46', '--front-deg must lie in [-45, 45], got -46'),
    ('RearNaN', '--rear-deg nan', '--rear-deg must be a finite number, got nan'),
    ('RearHuge', '--rear-deg 50', '--rear-deg must lie in [-45, 45], got 50'),
    ('TEndZero', '--t-end-s 0', '--t-end-s must lie in (0, 1e5] s, got 0'),
    ('TEndNegative', '--t-end-s -3', '--t-end-s must lie in (0, 1e5] s, got -3'),
    ('TEndNaN', '--t-end-s nan', '--t-end-s must be a finite number, got nan'),
    ('TEndHuge', '--t-end-s 1e9', '--t-end-s must lie in (0, 1e5] s, got 1000000000'),
    ('AccuracyZero', '--accuracy 0', '--accuracy must lie in (0, 1), got 0'),
    ('AccuracyOne', '--accuracy 1', '--accuracy must lie in (0, 1), got 1'),
    ('AccuracyNaN', '--accuracy nan', '--accuracy must be a finite number, got nan'),
    ('AccuracyNegative', '--accuracy -1e-6', '--accuracy must lie in (0, 1), got -1e-06'),
    ('IntegratorUnknown', '--integrator euler', "unknown integrator 'euler'"),
    ('IntegratorEmpty', '--integrator ""', "unknown integrator ''"),
    ('SemiExplicitEuler', '--integrator semi_explicit_euler2 --accuracy 1e-3', 'is refused for the chapter 3 vehicle'),
    ('Formulation', '--formulation rigid', "--formulation must be auto, constrained, reduced or dense, got 'rigid'"),
    ('Positional', 'stray', "unexpected argument 'stray'"),
    ('PositionalNumber', '10', "unexpected argument '10'"),
    ('UnknownOption', '--speed 3', 'bad command line'),
    ('SingleDash', '-out x', 'bad command line'),
    ('DataMissing', '--data nope.json', "data file 'nope.json' not found"),
]
for name, args, text in opt_cases:
    base = 'ch3_transient --no-plots --out {OUT} '
    if 'TEnd' not in name:
        base += '--t-end-s 0.01 '
    add(f'Ch3Option.{name}', 1, text, None, base + args)
for name, args, text in [
        ('ReportZero', '--report-interval-s 0', '--report-interval-s must be positive, got 0'),
        ('ReportNegative', '--report-interval-s -0.1', '--report-interval-s must be positive, got -0.1'),
        ('ReportTiny', '--report-interval-s 1e-7', '--report-interval-s = 1e-07 s gives 10000000 samples'),
        ('ReportNaN', '--report-interval-s nan', '--report-interval-s must be a finite number, got nan'),
        ('ReportAboveRun', '--t-end-s 0.5 --report-interval-s 2', '--report-interval-s (2 s) must not exceed the run'),
        ('TEndNegative', '--t-end-s -1', '--t-end-s must lie in (0, 1e5] s, got -1'),
        ('TEndInf', '--t-end-s inf', '--t-end-s must be a finite number, got inf'),
        ('AccuracyBig', '--accuracy 5', '--accuracy must lie in (0, 1), got 5'),
        ('IntegratorUnknown', '--integrator gear', "unknown integrator 'gear'"),
        ('Positional', 'extra', "unexpected argument 'extra'"),
        ('UnknownOption', '--speed-m-s 3', 'bad command line'),
]:
    add(f'QCOption.{name}', 1, text, None, 'quarter_car --no-plots --out {OUT} ' + args)

# other studies: options and positional arguments
for study, args, text in [
        ('ch3_steady_state', '--speed-m-s -1', '--speed-m-s must lie in [0.5, 100] m/s (a steady turn needs the tires rolling), got -1'),
        ('ch3_steady_state', '--front-deg nan', '--front-deg must be a finite number, got nan'),
        ('ch3_steady_state', 'stray', "unexpected argument 'stray'"),
        ('ch7_open_loop', '--speed-m-s 0', '--speed-m-s must lie in (0, 100] m/s, got 0'),
        ('ch7_open_loop', '--speed-m-s nan', '--speed-m-s must be a finite number, got nan'),
        ('ch7_open_loop', 'stray', "unexpected argument 'stray'"),
        ('ch7_open_loop', '--accuracy 0', '--accuracy must lie in (0, 1), got 0'),
        ('ch7_closed_loop', '--speed-m-s 500', '--speed-m-s must lie in (0, 100] m/s, got 500'),
        ('ch7_closed_loop', 'stray', "unexpected argument 'stray'"),
        ('ch7_closed_loop', '--integrator rk4', "unknown integrator 'rk4'"),
        ('ch8_maneuvers', 'stray', "unexpected argument 'stray'"),
        ('ch8_maneuvers', '--accuracy nan', '--accuracy must be a finite number, got nan'),
        ('ch4_sensitivity', 'stray', "unexpected argument 'stray'"),
        ('ch6_steering_ratio', 'stray', "unexpected argument 'stray'"),
        ('tire_curves', 'stray', "unexpected argument 'stray'"),
        ('tire_curves', '--data nope.json', "data file 'nope.json' not found"),
        ('steady_sweep', 'stray', "unexpected argument 'stray'"),
        ('steady_sweep', '--speed-step-m-s 1e-300', '--speed-step-m-s'),
        ('steady_sweep', '--speed-max-m-s 1e12', '--speed-max-m-s must lie in (0, 100] m/s, got 1000000000000'),
        ('steady_sweep', '--front-step-deg 0', '--front-step-deg must be positive, got 0'),
        ('steady_sweep', '--front-max-deg 90', '--front-max-deg must lie in [-45, 45], got 90'),
        ('steady_sweep', '--rear-ratio nan', '--rear-ratio must be a finite number, got nan'),
        ('steady_sweep', '--speed-min-m-s -5', '--speed-min-m-s must lie in (0, 100] m/s, got -5'),
        ('vdyn', 'walk', "unknown command 'walk'"),
]:
    tag = args.split()[0].lstrip('-').replace('-', '_')
    add(f'{study}.{tag}.{len(cases)}', 1, text, None, f'{study} --no-plots --out {{OUT}} {args}' if study not in ('ch3_steady_state', 'vdyn') else (f'{study} --out {{OUT}} {args}' if study != 'vdyn' else f'vdyn {args}'))

# --- output folder and full disk ------------------------------------------------------------------------
add('Output.Unwritable', 1, "cannot write", None, 'quarter_car --no-plots --t-end-s 0.01 --out {RO}')
add('Output.IsAFile', 1, 'cannot create output folder', None, 'quarter_car --no-plots --t-end-s 0.01 --out {FILE}')
add('Output.FullDiskSummary', 1, "cannot write '{OUT}/summary.json': write failed: No space left on device", None,
    'quarter_car --no-plots --t-end-s 0.01 --out {OUT} {FULL:summary.json}')
add('Output.FullDiskCsv', 1, "cannot write '{OUT}/history.csv': write failed: No space left on device", None,
    'quarter_car --no-plots --t-end-s 0.01 --out {OUT} {FULL:history.csv}')
add('Output.FullDiskCh3', 1, "No space left on device", None,
    'ch3_transient --no-plots --t-end-s 0.01 --out {OUT} {FULL:history.csv}')

cases = [c for c in cases if c is not None]
with open('cases.txt', 'w') as f:
    f.write('# Generated by generate_cases.py (see there for the format). name | exit | expected text | data file | command\n')
    for c in cases:
        f.write(' | '.join(str(x) for x in c) + '\n')
print(len(cases), 'cases')
