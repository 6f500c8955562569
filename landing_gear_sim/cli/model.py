"""The model and graph commands: simulate, rig, bode, params, campaign, convert, join."""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from landing_gear_sim.cli.common import (
    PROG,
    InputPath,
    add_params_arguments,
    add_run_arguments,
    add_storage_argument,
    check_outputs,
    mapping_of,
    note_if_compiling,
    params_of,
    progress,
    read_one,
    run_spec_of,
)
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.parameters import SPECS
from landing_gear_sim.model.runspec import RunSpec
from landing_gear_sim.ros.options import add_graph_arguments
from msg_tools.units import PA_PER_BAR

if TYPE_CHECKING:
    from landing_gear_sim.model.integrate import SimulationResult


def register(sub: argparse._SubParsersAction) -> None:
    """Add the sub-commands of this module to the ``landing-gear-sim`` parser."""
    _add_simulate(sub)
    _add_rig(sub)
    _add_bode(sub)
    _add_params(sub)
    _add_campaign(sub)
    _add_convert(sub)
    _add_join(sub)


def _add_simulate(sub: argparse._SubParsersAction) -> None:
    """``simulate``: one rig test, offline."""
    sim = sub.add_parser("simulate", help="simulate a rig test; write CSV (+ bag) and a plot")
    add_params_arguments(sim)
    add_run_arguments(sim)
    sim.add_argument("--noise-seed", type=int, help="seed of the sensor noise (sensors.*)")
    sim.add_argument("-o", "--output", type=Path, help="CSV path (default out/<name>.csv)")
    sim.add_argument("--bag", type=Path, help="also write a rosbag2 folder here")
    add_storage_argument(sim)
    sim.add_argument("--plot", type=Path, help="PNG path (default next to the CSV)")
    sim.add_argument("--no-plot", action="store_true", help="write no PNG")
    sim.set_defaults(func=cmd_simulate)


def _add_rig(sub: argparse._SubParsersAction) -> None:
    """``rig``: the ROS 2 node graph up for one run."""
    rig = sub.add_parser("rig", help="bring the ROS 2 node graph up for one run; record a bag")
    add_params_arguments(rig)
    add_run_arguments(rig)
    rig.add_argument("--replay", type=Path, metavar="RUN",
                     help="re-run a recorded rig test: its current drives the simulated graph")
    rig.add_argument("--bag", type=Path, help="bag folder (default out/rig/<run>_<time>)")
    rig.add_argument("--no-bag", action="store_true", help="run without the recorder")
    add_graph_arguments(rig)  # the launch file's arguments too
    rig.set_defaults(func=cmd_rig, launcher=True)


def _add_bode(sub: argparse._SubParsersAction) -> None:
    """``bode``: the frequency responses of paper Fig. 7."""
    bode = sub.add_parser("bode", help="frequency responses G_lambda, G_eta (paper Fig. 7)")
    add_params_arguments(bode)
    bode.add_argument("--speeds", type=float, nargs="+", default=[10.0, 30.0, 60.0],
                      help="operating speeds [m/s]")
    bode.add_argument("--slip", type=float, default=0.05, help="operating slip (default 0.05)")
    bode.add_argument("--fmin", type=float, default=0.1, help="lowest frequency [Hz] (0.1)")
    bode.add_argument("--fmax", type=float, default=100.0,
                      help="highest frequency [Hz] (100)")
    bode.add_argument("-o", "--output", type=Path, default=Path("out/bode.png"),
                      help="PNG path (default out/bode.png)")
    bode.set_defaults(func=cmd_bode)


def _add_params(sub: argparse._SubParsersAction) -> None:
    """``params``: the effective parameter set, shown or written."""
    show = sub.add_parser("params", help="show (or write) the effective parameter set")
    add_params_arguments(show)
    show.add_argument("--write", type=Path, help="write the merged set as a params file")
    show.set_defaults(func=cmd_params)


def _add_campaign(sub: argparse._SubParsersAction) -> None:
    """``campaign``: a synthetic campaign of the own generator."""
    gen = sub.add_parser("campaign", help="generate a synthetic rig campaign (own generator)")
    gen.add_argument("output", type=Path, help="new folder for the runs")
    add_params_arguments(gen)
    gen.add_argument("--seed", type=int, default=1,
                     help="the rig's deviations and the noise; the same seed, the same campaign")
    gen.add_argument("--deviation", type=float, default=0.03,
                     help="largest relative deviation of the rig from the datasheet")
    gen.add_argument("--logger", default="", metavar="KEY=VALUE,...",
                     help="log as a real logger does (the logger realities the diagnosis must "
                          "see through): rate_hz, encoder_counts (lines per revolution), "
                          "current_noise_a, current_adc_bits, current_range_a, "
                          "late=CHANNEL:SECONDS, dropout_s; e.g. rate_hz=200,encoder_counts=64")
    gen.add_argument("--light-runs", action="store_true",
                     help="also brake three stops at 70 %% of the static load (14, 21, 28 bar): "
                          "what shows a tyre's friction changing with the load")
    gen.add_argument("--shuffled", action="store_true",
                     help="make the runs in an order drawn from the seed, named run01_... in "
                          "it (a brake that wears, with --set brake.gain_drift_per_run=-0.03, "
                          "wears in that order)")
    one = gen.add_argument_group(
        "one run instead of the standard set (what a diagnosis proposes to run next)")
    add_run_arguments(one, default=None)
    gen.set_defaults(func=cmd_campaign)


def _add_convert(sub: argparse._SubParsersAction) -> None:
    """``convert``: a run from one format into another."""
    conv = sub.add_parser("convert", help="convert a run between CSV and rosbag2")
    conv.add_argument("input", type=InputPath, help="a run: CSV, bag folder or another format")
    conv.add_argument("output", type=Path, help="*.csv, *.txt, *.tsv (any case), or a "
                      "rosbag2 folder: a name without a suffix")
    add_storage_argument(conv)
    conv.add_argument("--mapping", type=InputPath, help="column-mapping file for a CSV input")
    conv.set_defaults(func=cmd_convert)


def _add_join(sub: argparse._SubParsersAction) -> None:
    """``join``: a recorded bag's segments into one file."""
    join = sub.add_parser("join", help="join a recorded bag's segments into one storage file "
                                       "(a long recording stopped by a signal keeps them)")
    join.add_argument("bag", type=InputPath, help="a bag folder")
    join.set_defaults(func=cmd_join)


def _summary(result: SimulationResult) -> str:
    peak_bar = result.pressure_pa.max() / PA_PER_BAR
    lines = [f"{result.scenario.name}: {len(result)} samples, {result.time_s[-1]:.3f} s "
             f"({result.stop_reason}); max pressure {peak_bar:.2f} bar"]
    if result.scenario.contact:
        braking = result.pressure_pa > 0.1 * PA_PER_BAR
        locked = (result.wheel_speed_rad_s <= 0) & braking
        lines.append(f"  speed {result.speed_m_s[0]:.2f} -> {result.speed_m_s[-1]:.2f} m/s, "
                     f"max slip {result.slip[braking].max() if braking.any() else 0.0:.3f}, "
                     f"wheel locked {locked.sum() / result.scenario.rate_hz:.3f} s")
    return "\n".join(lines)


def cmd_simulate(args: argparse.Namespace) -> int:
    import numpy as np

    from landing_gear_sim.model.integrate import simulate
    from landing_gear_sim.report.figures import plot_simulation
    from landing_gear_sim.ros.graph import load_scenario
    from msg_tools.bag_io import write_bag
    from msg_tools.csv_io import write_csv

    check_outputs(files=[args.output, args.plot])
    if args.bag and args.bag.exists():  # fail before anything is written
        raise LandingGearSimError(f"{args.bag}: exists already; remove it or choose another --bag")
    params = params_of(args)
    if args.profile == "file" and args.file is None:
        raise LandingGearSimError("--profile file needs --file RUN")
    scenario = load_scenario(run_spec_of(args), params)
    progress(f"simulating {scenario.name} (up to {scenario.duration_s:.1f} s at "
              f"{scenario.rate_hz:g} Hz)")
    started = time.perf_counter()
    with note_if_compiling():
        result = simulate(params, scenario)
    progress(f"simulated in {time.perf_counter() - started:.2f} s")
    output = args.output or Path("out") / f"{scenario.name}.csv"
    output.parent.mkdir(parents=True, exist_ok=True)
    run = result.to_run(np.random.default_rng(args.noise_seed))  # noise as sensors.* says
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
    from landing_gear_sim.ros.graph import (
        INCOMPLETE_BAG_EXIT,
        LOST_PEER_EXIT,
        NOT_STARTED_EXIT,
        RECORDER,
        GraphOptions,
        controlled_run,
        load_scenario,
    )
    from landing_gear_sim.ros.launcher import run_graph
    from landing_gear_sim.ros.options import given, graph_settings

    params = params_of(args)
    spec = run_spec_of(args)
    if args.replay is not None:
        spec = RunSpec(profile="file", file=str(args.replay), contact=spec.contact,
                       rate_hz=spec.rate_hz)
    spec = controlled_run(spec, args.controller)
    scenario = load_scenario(spec, params)  # fail here, not in five processes
    bag = None if args.no_bag else args.bag or Path("out") / "rig" / (
        f"{scenario.name}_{time.strftime('%Y%m%d-%H%M%S')}")
    if bag is not None and bag.exists():
        raise LandingGearSimError(f"{bag}: exists already; remove it or choose another --bag")
    options = GraphOptions(run=spec, bag=bag, replay=args.replay is not None,
                           **graph_settings(given(args)))
    source = {None: scenario.name, "external": "your controller"}.get(
        args.controller, f"the {args.controller} controller")  # not "external: ..." (issue 32)
    progress(f"{source} in the {args.clock} graph, up to {scenario.duration_s:.1f} s at "
             f"{scenario.rate_hz:g} Hz")
    started = time.perf_counter()
    outcome = run_graph(options, params, progress)
    wall = time.perf_counter() - started
    print(f"graph run: {wall:.1f} s wall; node exit codes: "
          + ", ".join(f"{name} {code}" for name, code in outcome.exit_codes.items()))
    recorded = bag if bag is not None and bag.exists() else None
    if recorded is not None:
        print(_bag_summary(recorded))
    if outcome.interrupted:
        held = ("the bag holds the run up to the stop" if recorded is not None
                else "stopped before anything was recorded")
        print(f"{PROG}: interrupted; {held}", file=sys.stderr)
        return 130
    if outcome.failed is not None:
        print(f"{PROG}: error: the run failed ({outcome.failed} exit code "
              f"{outcome.exit_codes[outcome.failed]})", file=sys.stderr)
        return 1
    if not outcome.ok:
        node = outcome.failing or "plant"
        code = outcome.exit_codes.get(node)
        why = {("plant", LOST_PEER_EXIT): "; a lost node's input was held, see above",
               ("plant", NOT_STARTED_EXIT): "; the run could not start, see above",
               (RECORDER, INCOMPLETE_BAG_EXIT): "; the bag lacks part of the run, see above",
               }.get((node, code or 0), "")
        print(f"{PROG}: error: the run failed ({node} exit code {code}{why})", file=sys.stderr)
        return 1
    return 0


def _bag_summary(bag: Path) -> str:
    from msg_tools.bag_read import read_bag
    from msg_tools.errors import RunFormatError

    try:
        run = read_bag(bag)
    except RunFormatError as exc:
        return f"bag: {bag} (not readable as a run: {exc})"
    return (f"bag: {bag} ({len(run)} samples, {run.time_s[-1] - run.time_s[0]:.3f} s, max "
            f"pressure {run.pressure_pa.max() / PA_PER_BAR:.2f} bar, flywheel "
            f"{run.flywheel_speed_rad_s[0]:.1f} -> {run.flywheel_speed_rad_s[-1]:.1f} rad/s)")


def cmd_bode(args: argparse.Namespace) -> int:
    import numpy as np

    from landing_gear_sim.model.linear import frequency_response, resonance_hz
    from landing_gear_sim.report.figures import plot_bode

    check_outputs(files=[args.output])
    params = params_of(args)
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
    from landing_gear_sim.diagnosis.terms import slot_notes

    check_outputs(files=[args.write])
    params = params_of(args)
    notes = slot_notes(params)  # what a slot's code names: '37.0' alone says nothing
    if args.write:
        params.to_yaml(args.write, notes=notes)
        print(f"wrote {args.write}")
        return 0
    print(f"# from: {', '.join(params.sources)}")
    for spec in SPECS:
        note = f"= {notes[spec.key]}: " if spec.key in notes and spec.key.endswith("_code") \
            else ""
        print(f"{spec.key:40s} {params[spec.key]!s:>14}  [{spec.unit}]  {note}"
              f"{spec.description}")
    return 0


def cmd_campaign(args: argparse.Namespace) -> int:
    import numpy as np

    from landing_gear_sim.calibration.campaign import (
        GENERATING_FILE,
        generate_campaign,
        generate_run,
        rig_like,
    )
    from landing_gear_sim.calibration.logger import Logger
    from landing_gear_sim.ros.graph import load_scenario

    if args.output.exists() and any(args.output.iterdir()):
        raise LandingGearSimError(f"{args.output}: exists and is not empty, not overwriting")
    if args.profile is not None and (args.light_runs or args.shuffled):
        raise LandingGearSimError("--profile writes one run: --light-runs and --shuffled are "
                                  "for the standard set")
    logger = Logger.parse(args.logger)
    rig = rig_like(params_of(args), np.random.default_rng(args.seed), args.deviation)
    realities = "".join(f", {words}" for words in logger.realities)
    what = "a synthetic campaign" if args.profile is None else f"one {args.profile} run"
    progress(f"simulating {what} (seed {args.seed}, datasheet ±{100 * args.deviation:g} %"
             f"{realities})")
    if args.profile is None:
        paths = generate_campaign(args.output, rig, args.seed, light=args.light_runs,
                                  logger=logger, shuffled=args.shuffled)
    else:
        spec = run_spec_of(args)
        spec = replace(spec, rate_hz=logger.rate_hz or spec.rate_hz)
        paths = [generate_run(args.output, rig, load_scenario(spec, rig), args.seed, logger)]
    for path in paths:
        print(f"  {path}")
    print(f"generating parameters (for checks only): {args.output / GENERATING_FILE}")
    return 0


TEXT_DELIMITERS = {".csv": ",", ".txt": ",", ".tsv": "\t"}
"""The text tables ``convert`` writes, by their suffix (any case, as the readers take it)."""


def cmd_convert(args: argparse.Namespace) -> int:
    from msg_tools.bag_io import write_bag
    from msg_tools.csv_io import write_csv

    suffix = args.output.suffix.lower()
    if suffix and suffix not in TEXT_DELIMITERS:
        raise LandingGearSimError(
            f"{args.output}: cannot write {args.output.suffix} files; convert writes "
            f"{', '.join(TEXT_DELIMITERS)} or a rosbag2 folder (a name without a suffix)")
    if args.output.exists():
        raise LandingGearSimError(f"{args.output}: exists already, not overwriting")
    check_outputs(folders=[args.output.parent])
    run = read_one(args.input, mapping_of(args))
    if suffix:
        write_csv(run, args.output, TEXT_DELIMITERS[suffix])
    else:
        write_bag(run, args.output, args.storage)
    print(f"{args.input} -> {args.output} ({len(run)} samples)")
    return 0


def cmd_join(args: argparse.Namespace) -> int:
    from msg_tools.bag_segments import join_bag

    files, messages = join_bag(args.bag, say=print)
    print(f"{args.bag}: one storage file already ({messages} messages)" if files == 1 else
          f"{args.bag}: {files} segments joined into one file ({messages} messages)")
    return 0
