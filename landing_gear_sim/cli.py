"""``landing-gear-sim``: the command-line front end.

Every user error ends as one line ``landing-gear-sim: error: ...`` and exit code 2.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.parameters import (
    ELEMENTS,
    SPECS,
    RigParameters,
    load_parameters,
    parse_assignment,
)
from landing_gear_sim.model.runspec import PROFILES, RunSpec, build_scenario
from msg_tools.csv_io import Mapping
from msg_tools.errors import RunFormatError

if TYPE_CHECKING:
    from antiskid.metrics import BrakingMetrics
    from landing_gear_sim.diagnosis.diagnose import Diagnosis
    from landing_gear_sim.model.integrate import SimulationResult
    from msg_tools.run import Run

PROG = "landing-gear-sim"

def _progress(message: str) -> None:
    print(f"[{PROG}] {message}", file=sys.stderr, flush=True)


def _add_params_arguments(parser: argparse.ArgumentParser, without: bool = True) -> None:
    parser.add_argument("--config", action="append", type=Path, metavar="FILE",
                        help="ROS 2 params file; repeat to layer (default: bundled reference rig)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override one parameter, e.g. --set friction.theta1=0.8")
    if without:
        parser.add_argument("--without", action="append", default=[], choices=ELEMENTS,
                            metavar="ELEMENT",
                            help=f"switch an element off ({', '.join(ELEMENTS)})")


def _add_run_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--profile", choices=[*PROFILES, "file"], default="constant",
                        help="valve current profile (default: constant)")
    parser.add_argument("--pressure-bar", type=float, default=30.0,
                        help="constant profile: target pressure (default 30 bar)")
    parser.add_argument("--current-a", type=float, help="constant profile: current instead")
    parser.add_argument("--file", type=Path,
                        help="--profile file: run (CSV or bag) whose current to use")
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--actuator-only", action="store_true", help="wheel off the flywheel")
    where.add_argument("--rig", action="store_true", help="wheel on the flywheel")
    parser.add_argument("--duration", type=float, help="input duration [s] (actuator tests)")
    parser.add_argument("--rate", type=float, help="output rate [Hz] (default from config)")


def _params(args: argparse.Namespace) -> RigParameters:
    overrides = dict(parse_assignment(text) for text in args.set)
    params = load_parameters(args.config, overrides or None)
    removed = getattr(args, "without", None)
    return params.without(*removed) if removed else params


def _build_scenario(args: argparse.Namespace, params: RigParameters) -> sc.Scenario:
    if args.profile == "file" and args.file is None:
        raise LandingGearSimError("--profile file needs --file RUN")
    return build_scenario(_run_spec(args), params)


def _run_spec(args: argparse.Namespace) -> RunSpec:
    contact = "actuator" if args.actuator_only else "rig" if args.rig else "auto"
    return RunSpec(profile=args.profile, pressure_pa=args.pressure_bar * 1e5,
                   current_a=math.nan if args.current_a is None else args.current_a,
                   file=str(args.file or ""), contact=contact,
                   duration_s=args.duration or 0.0, rate_hz=args.rate or 0.0)


def _summary(result: SimulationResult) -> str:
    lines = [f"{result.scenario.name}: {len(result)} samples, {result.time_s[-1]:.3f} s "
             f"({result.stop_reason}); max pressure {result.pressure_pa.max() / 1e5:.2f} bar"]
    if result.scenario.contact:
        braking = result.pressure_pa > 1e4
        locked = (result.wheel_speed_rad_s <= 0) & braking
        lines.append(f"  speed {result.speed_m_s[0]:.2f} -> {result.speed_m_s[-1]:.2f} m/s, "
                     f"max slip {result.slip[braking].max() if braking.any() else 0.0:.3f}, "
                     f"wheel locked {locked.sum() / result.scenario.rate_hz:.3f} s")
    return "\n".join(lines)


def cmd_simulate(args: argparse.Namespace) -> int:
    from landing_gear_sim.model.integrate import simulate
    from landing_gear_sim.report.figures import plot_simulation
    from msg_tools.bag_io import write_bag
    from msg_tools.csv_io import write_csv

    if args.bag and args.bag.exists():  # fail before anything is written
        raise LandingGearSimError(f"{args.bag}: exists already; remove it or choose another --bag")
    params = _params(args)
    scenario = _build_scenario(args, params)
    _progress(f"simulating {scenario.name} (up to {scenario.duration_s:.1f} s at "
              f"{scenario.rate_hz:g} Hz; the first run compiles the physics, ~10 s)")
    started = time.perf_counter()
    result = simulate(params, scenario)
    _progress(f"simulated in {time.perf_counter() - started:.2f} s")
    output = args.output or Path("out") / f"{scenario.name}.csv"
    output.parent.mkdir(parents=True, exist_ok=True)
    run = result.to_run(args.noise_seed)
    write_csv(run, output)
    print(_summary(result))
    print(f"  csv:  {output}")
    if args.bag:
        write_bag(run, args.bag, args.storage)
        print(f"  bag:  {args.bag} ({args.storage})")
    if not args.no_plot:
        plot = plot_simulation(result, args.plot or output.with_suffix(".png"))
        print(f"  plot: {plot}")
    return 0


def cmd_rig(args: argparse.Namespace) -> int:
    from landing_gear_sim.ros.graph import GraphOptions, controlled_run
    from landing_gear_sim.ros.launcher import run_graph

    params = _params(args)
    spec = _run_spec(args)
    if args.replay is not None:
        spec = RunSpec(profile="file", file=str(args.replay), contact=spec.contact,
                       rate_hz=spec.rate_hz)
    spec = controlled_run(spec, args.controller)
    scenario = build_scenario(spec, params)  # fail here, not in five processes
    bag = None if args.no_bag else args.bag or Path("out") / "rig" / (
        f"{scenario.name}_{time.strftime('%Y%m%d-%H%M%S')}")
    if bag is not None and bag.exists():
        raise LandingGearSimError(f"{bag}: exists already; remove it or choose another --bag")
    options = GraphOptions(run=spec, clock=args.clock, bag=bag, storage=args.storage,
                           sensor_noise=args.noise, timeout_s=args.timeout,
                           safe_pressure_pa=args.safe_pressure_bar * 1e5,
                           replay=args.replay is not None, controller=args.controller)
    _progress(f"{scenario.name}: {args.clock} graph, up to {scenario.duration_s:.1f} s at "
              f"{scenario.rate_hz:g} Hz")
    started = time.perf_counter()
    outcome = run_graph(options, params, _progress)
    wall = time.perf_counter() - started
    print(f"graph run: {wall:.1f} s wall; node exit codes: "
          + ", ".join(f"{name} {code}" for name, code in outcome.exit_codes.items()))
    if bag is not None:
        print(_bag_summary(bag))
    if outcome.interrupted:
        print(f"{PROG}: interrupted; the bag holds the run up to the stop", file=sys.stderr)
        return 130
    return 0 if outcome.ok else 1


def _bag_summary(bag: Path) -> str:
    from msg_tools.bag_io import read_bag

    try:
        run = read_bag(bag)
    except RunFormatError as exc:
        return f"bag: {bag} (not readable as a run: {exc})"
    return (f"bag: {bag} ({len(run)} samples, {run.time_s[-1]:.3f} s, max pressure "
            f"{run.pressure_pa.max() / 1e5:.2f} bar, flywheel {run.flywheel_speed_rad_s[0]:.1f}"
            f" -> {run.flywheel_speed_rad_s[-1]:.1f} rad/s)")


def cmd_metrics(args: argparse.Namespace) -> int:
    from antiskid.metrics import braking_metrics
    from msg_tools.io import read_run

    rig = _params(args)
    run = read_run(args.run, _mapping(args))
    metrics = braking_metrics(run, rig)
    print(_metrics_table({run.name: metrics}))
    _write_braking_outputs(args, run, rig, metrics)
    return 0


def cmd_antiskid(args: argparse.Namespace) -> int:
    from antiskid.closed_loop import (
        closed_loop,
        constant_pressure_baseline,
        make_controller,
        with_surface,
    )
    from antiskid.metrics import braking_metrics
    from msg_tools.csv_io import write_csv

    rig = with_surface(_params(args), args.surface)
    settings = dict(parse_assignment(text) for text in args.setting)
    step_s = 1.0 / (args.rate or rig.number("simulation.output_rate_hz"))
    controller = make_controller(args.controller, rig, step_s, settings)
    _progress(f"{args.controller} controller on the {args.surface} surface, closed loop")
    run = closed_loop(rig, controller, args.rate or 0.0).to_run()
    run = dataclasses.replace(run, name=f"{args.controller}_{args.surface}")
    metrics = braking_metrics(run, rig)
    _progress("constant-pressure baseline just below the skid pressure (bisection)")
    pressure, baseline = constant_pressure_baseline(rig)
    rows = {run.name: metrics,
            f"constant {pressure / 1e5:.1f} bar": braking_metrics(baseline.to_run(), rig)}
    print(_metrics_table(rows))
    if metrics.cycling_near_gear_walk:
        print(f"WARNING: pressure cycles at {metrics.cycling_frequency_hz:.1f} Hz, near the "
              f"gear-walk resonance ({metrics.gear_walk_frequency_hz:.1f} Hz)")
    output = args.output or Path("out") / f"{run.name}.csv"
    output.parent.mkdir(parents=True, exist_ok=True)
    write_csv(run, output)
    print(f"  csv:  {output}")
    _write_braking_outputs(args, run, rig, metrics, output.with_suffix(".png"))
    return 0


def _metrics_table(rows: dict[str, BrakingMetrics]) -> str:
    header = (f"{'run':24s} {'eff':>5s} {'mu':>5s} {'stop m':>7s} {'stop s':>6s} "
              f"{'decel':>6s} {'slip rms':>8s} {'max':>5s} {'locks':>5s} {'cycling Hz':>10s}")
    lines = [header]
    for name, m in rows.items():
        lines.append(f"{name:24s} {m.braking_efficiency:5.3f} {m.mean_friction:5.3f} "
                     f"{m.stopping_distance_m:7.1f} {m.stopping_time_s:6.2f} "
                     f"{m.mean_deceleration_m_s2:6.2f} {m.slip_rms:8.3f} {m.slip_max:5.3f} "
                     f"{m.lock_events:5d} {m.cycling_frequency_hz:10.2f}")
    return "\n".join(lines)


def _write_braking_outputs(args: argparse.Namespace, run: Run, rig: RigParameters,
                           metrics: BrakingMetrics, default_plot: Path | None = None) -> None:
    import json

    from antiskid.plotting import plot_braking

    from antiskid.metrics import slip_from, speeds_m_s

    if args.json:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(metrics.to_dict(), indent=1))
        print(f"  json: {args.json}")
    plot = args.plot or default_plot
    if plot is not None:
        vehicle, wheel = speeds_m_s(run, rig)
        path = plot_braking(run, slip_from(vehicle, wheel), wheel, vehicle, metrics, plot)
        print(f"  plot: {path}")


def cmd_bode(args: argparse.Namespace) -> int:
    from landing_gear_sim.model.linear import frequency_response, resonance_hz
    from landing_gear_sim.report.figures import plot_bode

    params = _params(args)
    frequencies = np.logspace(np.log10(args.fmin), np.log10(args.fmax), 800)
    variants = [params] if not params.has("gear_walk") else [params, params.without("gear_walk")]
    responses = [frequency_response(v, speed, frequencies, args.slip)
                 for speed in args.speeds for v in variants]
    for response in responses:
        peak = resonance_hz(response)
        where = f"resonance {peak:.2f} Hz" if peak else "no resonance"
        print(f"{response.speed_m_s:6.1f} m/s, {'with' if response.gear_walk else 'without'} "
              f"gear walk: |G_lambda(0)| = {abs(response.slip[0]):.3g} 1/(N m), {where}")
    print(f"plot: {plot_bode(responses, args.output)}")
    return 0


def cmd_params(args: argparse.Namespace) -> int:
    params = _params(args)
    if args.write:
        params.to_yaml(args.write)
        print(f"wrote {args.write}")
        return 0
    print(f"# from: {', '.join(params.sources)}")
    for spec in SPECS:
        print(f"{spec.key:40s} {params[spec.key]!s:>14}  [{spec.unit}]  {spec.description}")
    return 0


def _mapping(args: argparse.Namespace) -> Mapping | None:
    from msg_tools.csv_io import read_mapping

    return read_mapping(args.mapping) if getattr(args, "mapping", None) else None


def _write_atomically(path: Path, write: Callable[[Path], None]) -> None:
    """Write via a temporary file so a failure never leaves a half-written ``path``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".part")
    write(tmp)
    tmp.replace(path)


def cmd_identify(args: argparse.Namespace) -> int:
    import json

    from landing_gear_sim.calibration.identify import identify
    from landing_gear_sim.report.validation import estimates_table, text_table
    from msg_tools.io import read_campaign

    campaign = read_campaign(args.campaign, _mapping(args))
    for problem in campaign.problems:
        _progress(f"skipped: {problem}")
    started = time.perf_counter()
    result = identify(campaign.runs, _params(args), args.fix_theta3, _progress)
    for name, kind in result.classes.items():
        print(f"  {name:28s} {kind}")
    for problem in result.problems:
        print(f"  note: {problem}")
    if not result.estimates:
        raise LandingGearSimError(f"{args.campaign}: no identification step could run; "
                                  f"nothing written")
    print(text_table(["parameter", "value", "1-sigma", "method", "runs"],
                     estimates_table(result.estimates)))
    _write_atomically(args.output, result.params.to_yaml)
    evidence = {"campaign": str(args.campaign), "classes": result.classes,
                "problems": [*campaign.problems, *result.problems],
                "estimates": [{"key": e.key, "value": e.value, "std": e.std,
                               "method": e.method, "runs": list(e.runs)}
                              for e in result.estimates]}
    sidecar = args.output.with_suffix(".identification.json")
    _write_atomically(sidecar, lambda p: p.write_text(json.dumps(evidence, indent=1)))
    print(f"identified in {time.perf_counter() - started:.1f} s")
    print(f"params:   {args.output}\nevidence: {sidecar}")
    return 0


def cmd_validate(args: argparse.Namespace) -> int:
    from landing_gear_sim.calibration.identify import _braking, friction_samples
    from landing_gear_sim.calibration.validate import CHANNELS, validate
    from landing_gear_sim.report.validation import (
        html_image,
        html_table,
        plot_friction,
        plot_overlay,
        scores_table,
        text_table,
        write_html,
    )
    from msg_tools.io import read_campaign

    campaign = read_campaign(args.campaign, _mapping(args))
    params = _params(args)
    _progress(f"simulating {len(campaign.runs)} runs with their measured inputs")
    comparisons = validate(campaign.runs, params)
    header = ["run", "kind", *(c.split("_")[0] + " fit %" for c in CHANNELS)]
    rows = scores_table(comparisons)
    print(text_table(header, rows))
    report = args.report
    sections = [("Model", html_table(["parameters from"], [[", ".join(params.sources)]])),
                ("Fit per run and channel", html_table(header, rows))]
    braking = [c.measured for c in comparisons if c.kind.startswith("brake")]
    if braking:
        slip, mu = friction_samples([_braking(r, params) for r in braking], params)
        figure = plot_friction(slip, mu, params, report / "friction.png")
        sections.append(("Friction curve", html_image(figure, report)))
    for c in comparisons:
        figure = plot_overlay(c, report / f"{c.measured.name}.png")
        sections.append((f"{c.measured.name}", html_image(figure, report)))
    page = write_html(report / "index.html", f"Validation of {args.campaign}", sections)
    print(f"report: {page}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from landing_gear_sim.calibration.validate import compare
    from landing_gear_sim.report.validation import plot_overlay, text_table
    from msg_tools.io import read_run

    measured, simulated = read_run(args.measured, _mapping(args)), read_run(args.simulated)
    comparison = compare(measured, simulated)
    rows = [[channel, f"{s.fit_percent:.2f}", f"{s.rmse:.4g}", f"{s.max_error:.4g}"]
            for channel, s in comparison.scores.items()]
    print(text_table(["channel (SI)", "fit %", "RMSE", "max |error|"], rows))
    print(f"plot: {plot_overlay(comparison, args.plot)}")
    return 0


def cmd_campaign(args: argparse.Namespace) -> int:
    from landing_gear_sim.calibration.campaign import GENERATING_FILE, generate_campaign, rig_like

    if args.output.exists() and any(args.output.iterdir()):
        raise LandingGearSimError(f"{args.output}: exists and is not empty, not overwriting")
    rig = rig_like(_params(args), np.random.default_rng(args.seed), args.deviation)
    _progress(f"simulating a synthetic campaign (seed {args.seed}, datasheet "
              f"±{100 * args.deviation:g} %)")
    for path in generate_campaign(args.output, rig, args.seed):
        print(f"  {path}")
    print(f"generating parameters (for checks only): {args.output / GENERATING_FILE}")
    return 0


def cmd_convert(args: argparse.Namespace) -> int:
    from msg_tools.bag_io import write_bag
    from msg_tools.csv_io import write_csv
    from msg_tools.io import read_run

    run = read_run(args.input, _mapping(args))
    if args.output.exists():
        raise LandingGearSimError(f"{args.output}: exists already, not overwriting")
    if args.output.suffix == ".csv":
        write_csv(run, args.output)
    else:
        write_bag(run, args.output, args.storage)
    print(f"{args.input} -> {args.output} ({len(run)} samples)")
    return 0


def cmd_diagnose(args: argparse.Namespace) -> int:
    import json

    from landing_gear_sim.diagnosis.diagnose import diagnose
    from msg_tools.io import read_runs

    campaign = read_runs(args.runs, _mapping(args))
    for problem in campaign.problems:
        _progress(f"skipped: {problem}")
    started = time.perf_counter()
    result = diagnose(campaign.runs, _params(args), args.start_without,
                      lambda m: _progress(f"[{time.perf_counter() - started:5.1f} s] {m}"))
    result.problems[:0] = campaign.problems
    print(_diagnosis_summary(result))
    document = result.to_json()
    if args.json:
        _write_atomically(args.json, lambda p: p.write_text(json.dumps(document, indent=1)))
        print(f"json:   {args.json}")
    if args.report:
        _progress("writing the report")
        page = _diagnosis_report(result, campaign.runs, args.report)
        print(f"report: {page}")
    if args.output:
        _write_atomically(args.output, result.extended.to_yaml)
        print(f"extended model: {args.output}")
    print(f"diagnosed {len(campaign.runs)} runs in {time.perf_counter() - started:.1f} s")
    return 0


def _diagnosis_summary(result: Diagnosis) -> str:
    from landing_gear_sim.report.validation import text_table

    def fits(values: dict[str, float]) -> str:
        return ", ".join(f"{c.split('_')[0]} {v:.1f}" for c, v in values.items())

    rows = [[f.cause, "yes" if f.accepted else "no", _maybe(f.delta_bic),
             _maybe(f.held_out), f"{fits(f.fit_before)} -> {fits(f.fit_after)}"]
            for f in result.candidates]
    lines = ["candidates:", text_table(["cause", "accepted", "dBIC", "held-out", "held-out fit %"],
                                       rows) if rows else "  (none: the model has them all)"]
    lines.append(f"baseline fit %: {fits(result.baseline)}")
    lines.append(f"VERDICT: {result.verdict}")
    for f in result.findings:
        values = ", ".join(f"{k} = {v:.6g}" + (f" ± {f.std[k]:.2g}" if k in f.std else "")
                           for k, v in f.parameters.items())
        lines.append(f"  {f.cause}: {values}")
        if f.fit_after and f.fit_after != f.fit_before:
            gain = ", ".join(f"{c} {f.fit_before[c]:.2f} -> {f.fit_after[c]:.2f} %"
                             for c in f.fit_after)
            lines.append(f"    held-out gain: {gain}")
        lines.append(f"    evidence: {f.evidence}")
    for problem in result.problems:
        lines.append(f"  note: {problem}")
    return "\n".join(lines)


def _maybe(value: float | None) -> str:
    return "-" if value is None else f"{value:+.0f}"


def _diagnosis_report(result: Diagnosis, runs: Sequence[Run], folder: Path) -> Path:
    from landing_gear_sim.diagnosis.diagnose import report_sections
    from landing_gear_sim.report.validation import write_html

    sections = report_sections(result, runs, folder)
    return write_html(folder / "index.html", f"Diagnosis: {result.verdict}", sections)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description="Landing-gear anti-skid rig "
                                     "digital twin: simulate, analyse, compare.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = parser.add_subparsers(dest="command", required=True)

    sim = sub.add_parser("simulate", help="simulate a rig test; write CSV (+ bag) and a plot")
    _add_params_arguments(sim)
    _add_run_arguments(sim)
    sim.add_argument("--noise-seed", type=int, help="seed of the sensor noise (sensors.*)")
    sim.add_argument("-o", "--output", type=Path, help="CSV path (default out/<name>.csv)")
    sim.add_argument("--bag", type=Path, help="also write a rosbag2 folder here")
    sim.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    sim.add_argument("--plot", type=Path, help="PNG path (default next to the CSV)")
    sim.add_argument("--no-plot", action="store_true")
    sim.set_defaults(func=cmd_simulate)

    rig = sub.add_parser("rig", help="bring the ROS 2 node graph up for one run; record a bag")
    _add_params_arguments(rig)
    _add_run_arguments(rig)
    rig.add_argument("--replay", type=Path, metavar="RUN",
                     help="re-run a recorded rig test: its current drives the simulated graph")
    rig.add_argument("--controller", choices=["threshold", "slip"],
                     help="anti-skid controller in closed loop instead of a profile")
    rig.add_argument("--clock", choices=["lockstep", "realtime"], default="lockstep",
                     help="lockstep: sim time, deterministic (default); realtime: wall clock")
    rig.add_argument("--bag", type=Path, help="bag folder (default out/rig/<run>_<time>)")
    rig.add_argument("--no-bag", action="store_true", help="run without the recorder")
    rig.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    rig.add_argument("--noise", action="store_true", help="add the sensors.* noise")
    rig.add_argument("--timeout", type=float, default=10.0,
                     help="lockstep: seconds to wait for a silent node before holding its input")
    rig.add_argument("--safe-pressure-bar", type=float, default=0.0,
                     help="brake pressure applied once the actuator is lost (default 0)")
    rig.set_defaults(func=cmd_rig)

    met = sub.add_parser("metrics", help="braking metrics of a run (efficiency, locks, ...)")
    met.add_argument("run", type=Path, help="CSV or bag of a braking run")
    _add_params_arguments(met)
    met.add_argument("--mapping", type=Path, help="column-mapping file for a CSV")
    met.add_argument("--plot", type=Path, help="PNG like the paper's Fig. 1")
    met.add_argument("--json", type=Path, help="write the metrics as JSON")
    met.set_defaults(func=cmd_metrics)

    anti = sub.add_parser("antiskid", help="an anti-skid controller against the rig model, "
                          "offline; metrics against a constant-pressure stop")
    anti.add_argument("--controller", choices=["threshold", "slip"], default="threshold")
    anti.add_argument("--surface", choices=["dry", "wet", "snow"], default="dry",
                      help="runway friction curve (dry: the rig's own)")
    _add_params_arguments(anti)
    anti.add_argument("--setting", action="append", default=[], metavar="KEY=VALUE",
                      help="controller setting, e.g. --setting slip_setpoint=0.1")
    anti.add_argument("--rate", type=float, help="controller rate [Hz] (default from config)")
    anti.add_argument("-o", "--output", type=Path, help="CSV of the run (default out/)")
    anti.add_argument("--plot", type=Path, help="PNG (default next to the CSV)")
    anti.add_argument("--json", type=Path, help="write the metrics as JSON")
    anti.set_defaults(func=cmd_antiskid)

    bode = sub.add_parser("bode", help="frequency responses G_lambda, G_eta (paper Fig. 7)")
    _add_params_arguments(bode)
    bode.add_argument("--speeds", type=float, nargs="+", default=[10.0, 30.0, 60.0],
                      help="operating speeds [m/s]")
    bode.add_argument("--slip", type=float, default=0.05, help="operating slip (default 0.05)")
    bode.add_argument("--fmin", type=float, default=0.1)
    bode.add_argument("--fmax", type=float, default=100.0)
    bode.add_argument("-o", "--output", type=Path, default=Path("out/bode.png"))
    bode.set_defaults(func=cmd_bode)

    ident = sub.add_parser("identify", help="calibrate the model on a campaign folder")
    ident.add_argument("campaign", type=Path, help="folder of runs (CSV files, bags)")
    _add_params_arguments(ident)
    ident.add_argument("-o", "--output", type=Path, default=Path("out/calibrated.yaml"))
    ident.add_argument("--fix-theta3", action="store_true", help="keep Burckhardt theta3")
    ident.add_argument("--mapping", type=Path, help="column-mapping file for the CSVs")
    ident.set_defaults(func=cmd_identify)

    val = sub.add_parser("validate", help="simulate a campaign with its inputs; fit report")
    val.add_argument("campaign", type=Path)
    _add_params_arguments(val)
    val.add_argument("--report", type=Path, default=Path("out/validation"))
    val.add_argument("--mapping", type=Path, help="column-mapping file for the CSVs")
    val.set_defaults(func=cmd_validate)

    cmp_ = sub.add_parser("compare", help="fit per channel of a simulated vs a measured run")
    cmp_.add_argument("measured", type=Path)
    cmp_.add_argument("simulated", type=Path)
    cmp_.add_argument("--plot", type=Path, default=Path("out/compare.png"))
    cmp_.add_argument("--mapping", type=Path, help="column-mapping file for MEASURED")
    cmp_.set_defaults(func=cmd_compare)

    gen = sub.add_parser("campaign", help="generate a synthetic rig campaign (own generator)")
    gen.add_argument("output", type=Path, help="new folder for the runs")
    _add_params_arguments(gen)
    gen.add_argument("--seed", type=int, default=1)
    gen.add_argument("--deviation", type=float, default=0.03,
                     help="largest relative deviation of the rig from the datasheet")
    gen.set_defaults(func=cmd_campaign)

    conv = sub.add_parser("convert", help="convert a run between CSV and rosbag2")
    conv.add_argument("input", type=Path)
    conv.add_argument("output", type=Path, help="*.csv, or a bag folder")
    conv.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    conv.add_argument("--mapping", type=Path, help="column-mapping file for a CSV input")
    conv.set_defaults(func=cmd_convert)

    diag = sub.add_parser("diagnose", help="why model and rig disagree: cause, extension, gain")
    diag.add_argument("runs", type=Path, nargs="+", metavar="RUN",
                      help="CSV files, bags, or campaign folders")
    _add_params_arguments(diag, without=False)
    diag.add_argument("--without", action="extend", nargs="+", default=[], metavar="ELEMENT",
                      dest="start_without",
                      help="start from a model without these elements, e.g. gear_walk, "
                      "friction_curve (the diagnosis must then rediscover them)")
    diag.add_argument("--json", type=Path, help="write the diagnosis contract JSON here")
    diag.add_argument("--report", type=Path, help="write the HTML report into this folder")
    diag.add_argument("-o", "--output", type=Path, help="write the extended model (params)")
    diag.add_argument("--mapping", type=Path, help="column-mapping file for the CSVs")
    diag.set_defaults(func=cmd_diagnose)

    show = sub.add_parser("params", help="show (or write) the effective parameter set")
    _add_params_arguments(show)
    show.add_argument("--write", type=Path, help="write the merged set as a params file")
    show.set_defaults(func=cmd_params)
    return parser


def _version() -> str:
    from landing_gear_sim import __version__

    return __version__


def _check(args: argparse.Namespace, parser: argparse.ArgumentParser) -> None:
    if args.command == "simulate":
        if args.rate is not None and args.rate <= 0:
            parser.error("--rate must be > 0")
        if args.duration is not None and args.duration <= 0:
            parser.error("--duration must be > 0")
    if args.command == "bode":
        if not 0 < args.slip < 1:
            parser.error("--slip must be in (0, 1)")
        if not 0 < args.fmin < args.fmax:
            parser.error("need 0 < --fmin < --fmax")
        if any(v <= 0 for v in args.speeds):
            parser.error("--speeds must be > 0")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    _check(args, parser)
    try:
        return int(args.func(args))
    except (LandingGearSimError, RunFormatError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130


def _entry(command: str) -> Callable[[], int]:
    def run() -> int:
        return main([command, *sys.argv[1:]])

    return run


simulate_main = _entry("simulate")
bode_main = _entry("bode")
