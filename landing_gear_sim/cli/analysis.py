"""The analysis commands: identify, validate, compare, diagnose, metrics, antiskid."""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path
from typing import TYPE_CHECKING

from landing_gear_sim.cli.common import (
    InputPath,
    add_params_arguments,
    check_outputs,
    mapping_of,
    params_of,
    progress,
    read_one,
    write_atomically,
)
from landing_gear_sim.errors import IdentificationError, LandingGearSimError
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import RigParameters, parse_assignment
from msg_tools.units import PA_PER_BAR

if TYPE_CHECKING:
    from antiskid.metrics import BrakingMetrics
    from landing_gear_sim.calibration.identify import Identification
    from msg_tools.run import Run


def register(sub: argparse._SubParsersAction) -> None:
    """Add the sub-commands of this module to the ``landing-gear-sim`` parser."""
    _add_identify(sub)
    _add_validate(sub)
    _add_compare(sub)
    _add_diagnose(sub)
    _add_metrics(sub)
    _add_antiskid(sub)


def _add_identify(sub: argparse._SubParsersAction) -> None:
    """``identify``: calibrate the model on a campaign."""
    ident = sub.add_parser("identify", help="calibrate the model on a campaign folder")
    ident.add_argument("campaign", type=InputPath, help="folder of runs (CSV files, bags)")
    add_params_arguments(ident)
    ident.add_argument("-o", "--output", type=Path, default=Path("out/calibrated.yaml"),
                       help="calibrated params file (default out/calibrated.yaml)")
    ident.add_argument("--fix-theta3", action="store_true", help="keep Burckhardt theta3")
    ident.add_argument("--mapping", type=InputPath, help="column-mapping file for the CSVs")
    ident.add_argument("--partial", action="store_true",
                       help="write the parameters a campaign could identify even when a step "
                       "was skipped or failed (the file lists what kept its base value)")
    ident.set_defaults(func=cmd_identify)


def _add_validate(sub: argparse._SubParsersAction) -> None:
    """``validate``: a campaign simulated with its inputs, its fit report."""
    val = sub.add_parser("validate", help="simulate a campaign with its inputs; fit report")
    val.add_argument("campaign", type=InputPath, help="folder of runs (CSV files, bags)")
    add_params_arguments(val)
    val.add_argument("--report", type=Path, default=Path("out/validation"),
                     help="folder of the HTML fit report (default out/validation)")
    val.add_argument("--mapping", type=InputPath, help="column-mapping file for the CSVs")
    val.set_defaults(func=cmd_validate)


def _add_compare(sub: argparse._SubParsersAction) -> None:
    """``compare``: one simulated run against one measured."""
    cmp_ = sub.add_parser("compare", help="fit per channel of a simulated vs a measured run")
    cmp_.add_argument("measured", type=InputPath, help="the rig's run (CSV or bag)")
    cmp_.add_argument("simulated", type=InputPath, help="the model's run of the same input")
    cmp_.add_argument("--plot", type=Path, default=Path("out/compare.png"),
                      help="PNG path (default out/compare.png)")
    cmp_.add_argument("--mapping", type=InputPath, help="column-mapping file for MEASURED")
    add_params_arguments(cmp_, without=False)  # the rig MEASURED comes from: its units checked
    cmp_.set_defaults(func=cmd_compare)


def _add_diagnose(sub: argparse._SubParsersAction) -> None:
    """``diagnose``: why model and rig disagree (its help lists the verdicts)."""
    diag = sub.add_parser("diagnose", help="why model and rig disagree: cause, extension, gain")
    diag.add_argument("runs", type=InputPath, nargs="+", metavar="RUN",
                      help="CSV files, bags, or campaign folders")
    add_params_arguments(diag, without=False)
    diag.add_argument("--without", action="extend", type=_names, default=[],
                      metavar="ELEMENT[,ELEMENT...]", dest="start_without",
                      help="start from a model without these elements (one value: repeat the "
                      "option or separate with commas), e.g. gear_walk, friction_curve: the "
                      "diagnosis must then rediscover them")
    diag.add_argument("--json", type=Path, help="write the diagnosis contract JSON here")
    diag.add_argument("--report", type=Path, help="write the HTML report into this folder")
    diag.add_argument("-o", "--output", type=Path, help="write the extended model (params)")
    diag.add_argument("--mapping", type=InputPath, help="column-mapping file for the CSVs")
    diag.set_defaults(func=cmd_diagnose)
    plain_help = diag.format_help
    diag.format_help = lambda: plain_help() + "\n" + _diagnose_kinds()


def _add_metrics(sub: argparse._SubParsersAction) -> None:
    """``metrics``: braking metrics of one run."""
    met = sub.add_parser("metrics", help="braking metrics of a run (efficiency, locks, ...)")
    met.add_argument("run", type=InputPath, help="CSV or bag of a braking run")
    add_params_arguments(met)
    met.add_argument("--mapping", type=InputPath, help="column-mapping file for a CSV")
    met.add_argument("--plot", type=Path, help="PNG like the paper's Fig. 1")
    met.add_argument("--json", type=Path, help="write the metrics as JSON")
    met.set_defaults(func=cmd_metrics)


def _add_antiskid(sub: argparse._SubParsersAction) -> None:
    """``antiskid``: a controller against the rig model, offline."""
    anti = sub.add_parser("antiskid", help="an anti-skid controller against the rig model, "
                          "offline; metrics against a constant-pressure stop")
    anti.add_argument("--controller", choices=["threshold", "slip"], default="threshold",
                      help="anti-skid logic (default threshold)")
    anti.add_argument("--surface", choices=["dry", "wet", "snow"], default="dry",
                      help="runway friction curve (dry: the rig's own)")
    add_params_arguments(anti)
    anti.add_argument("--setting", action="append", default=[], metavar="KEY=VALUE",
                      help="controller setting, e.g. --setting slip_setpoint=0.1")
    anti.add_argument("--rate", type=float, help="controller rate [Hz] (default from config)")
    anti.add_argument("-o", "--output", type=Path, help="CSV of the run (default out/)")
    anti.add_argument("--plot", type=Path, help="PNG (default next to the CSV)")
    anti.add_argument("--json", type=Path, help="write the metrics as JSON")
    anti.set_defaults(func=cmd_antiskid)


def cmd_identify(args: argparse.Namespace) -> int:
    import json

    from landing_gear_sim.calibration.identify import identify
    from landing_gear_sim.report.pages import text_table
    from landing_gear_sim.report.validation_tables import estimates_table
    from msg_tools.io import read_campaign

    check_outputs(files=[args.output])

    campaign = read_campaign(args.campaign, mapping_of(args))
    for line in campaign.said():
        progress(line)
    started = time.perf_counter()
    result = identify(campaign.runs, params_of(args), args.fix_theta3, progress)
    for name, kind in result.classes.items():
        print(f"  {name:28s} {kind}")
    for problem in result.problems:
        print(f"  note: {problem}")
    if not result.estimates:
        raise LandingGearSimError(f"{args.campaign}: no identification step could run; "
                                  f"nothing written")
    if not result.complete and not args.partial:
        raise IdentificationError(
            f"{args.campaign}: not identified: {'; '.join(result.not_identified)} (see the "
            "notes above); nothing written. --partial writes the rest, marking these")
    print(text_table(["parameter", "value", "1-sigma", "method", "runs"],
                     estimates_table(result.estimates)))
    write_atomically(args.output, lambda path: _write_params(result, path))
    evidence = result.to_json(str(args.campaign), campaign.problems)
    sidecar = args.output.with_suffix(".identification.json")
    write_atomically(sidecar, lambda p: p.write_text(json.dumps(evidence, indent=1)))
    print(f"identified in {time.perf_counter() - started:.1f} s")
    print(f"params:   {args.output}\nevidence: {sidecar}")
    return 0


def _write_params(result: Identification, path: Path) -> None:
    """The params file; a partial one starts with the steps whose values were kept."""
    from landing_gear_sim.diagnosis.terms import slot_notes

    header = ["PARTIAL identification (--partial): these steps did not run, their parameters "
              "keep the base values:", *(f"  {step}" for step in result.not_identified)
              ] if result.not_identified else []
    result.params.to_yaml(path, header=header, notes=slot_notes(result.params))


def cmd_validate(args: argparse.Namespace) -> int:
    from landing_gear_sim.calibration.validate import channel_verdicts, validate_campaign
    from landing_gear_sim.report.pages import text_table
    from landing_gear_sim.report.validation import write_validation_report
    from landing_gear_sim.report.validation_tables import (
        scores_header,
        scores_table,
        validation_sentence,
        verdict_table,
    )
    from msg_tools.io import read_campaign

    check_outputs(folders=[args.report])
    campaign = read_campaign(args.campaign, mapping_of(args))
    for line in campaign.said():
        progress(line)
    params = params_of(args)
    progress(f"simulating {len(campaign.runs)} runs with their measured inputs")
    validation = validate_campaign(campaign.runs, params)
    print(text_table(scores_header(), scores_table(validation.comparisons)))
    verdicts = channel_verdicts(validation.comparisons)
    print(f"\n{text_table(*verdict_table(verdicts))}\n{validation_sentence(verdicts)}")
    page = write_validation_report(validation, args.report, f"Validation of {args.campaign}")
    print(f"report: {page}")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    from landing_gear_sim.calibration.measured import channel_words
    from landing_gear_sim.calibration.plausibility import check_units
    from landing_gear_sim.calibration.runs import classified
    from landing_gear_sim.calibration.validate import NOISE_MULTIPLE, compare
    from landing_gear_sim.report.pages import text_table
    from landing_gear_sim.report.validation import plot_overlay
    from msg_tools.units import DISPLAY_UNITS

    check_outputs(files=[args.plot])
    measured = classified(read_one(args.measured, mapping_of(args)))  # once: compare keeps it
    check_units([measured], params_of(args))  # before a fit % of −600,000
    comparison = compare(measured, read_one(args.simulated))
    for note in comparison.notes:
        progress(f"note: {note}")
    rows = []
    for channel, score in comparison.scores.items():
        factor, unit = DISPLAY_UNITS[channel]  # as the plot shows it (issue 32: Pa and N)
        rows.append([channel_words(channel), f"{score.fit_percent:.2f}",
                     f"{score.rmse * factor:.4g} {unit}", f"{score.max_error * factor:.4g} {unit}",
                     f"{score.in_noise:.3g} × noise: {'pass' if score.passed else 'FAIL'}"])
    print(text_table(["channel", "fit %", "RMSE", "max |error|",
                      f"RMSE within {NOISE_MULTIPLE:g} × the logger's noise"], rows))
    print(f"plot: {plot_overlay(comparison, args.plot)}")
    return 0


def _diagnose_kinds() -> str:
    """What a verdict can be and what a diagnosis may start without, for diagnose's help
    (from the catalogue and the families' registry, read only when the help is asked for:
    they load the numerical stack)."""
    import textwrap

    from landing_gear_sim.diagnosis.catalogue import CATALOGUE
    from landing_gear_sim.diagnosis.families import REGISTRY
    from landing_gear_sim.diagnosis.start import REMOVABLE

    families = dict.fromkeys(name for f in REGISTRY
                             for name in (f.reports, *f.words, *(h.family for h in f.hidden)))
    lines = [
        "verdicts: a catalogue element (" + ", ".join(CATALOGUE) + "); discovered, with "
        "its family (" + ", ".join(families) + "); unexplained (the equation the evidence "
        "lives in); none; inconclusive (what the campaign cannot test, and what would)",
        "--without elements: " + ", ".join(REMOVABLE)]
    return "\n".join(textwrap.fill(line, 79, subsequent_indent="  ") for line in lines) + "\n"


def _names(text: str) -> list[str]:
    """One ``--without`` value: a name or a comma-separated list (a value per option, so
    that the option never takes the campaign after it for an element)."""
    return [name.strip() for name in text.split(",") if name.strip()]


def cmd_diagnose(args: argparse.Namespace) -> int:
    import json

    from landing_gear_sim.diagnosis.start import starting_model

    check_outputs(files=[args.json, args.output], folders=[args.report])
    base = params_of(args)
    starting_model(base, args.start_without)  # a misspelt element: at once

    from landing_gear_sim.diagnosis.diagnose import diagnose
    from landing_gear_sim.report.model_file import write_extended_model
    from landing_gear_sim.report.summary import diagnosis_summary
    from msg_tools.io import read_runs

    campaign = read_runs(args.runs, mapping_of(args))
    for line in campaign.said():
        progress(line)
    started = time.perf_counter()
    result = diagnose(campaign.runs, base, args.start_without,
                      lambda m: progress(f"[{time.perf_counter() - started:5.1f} s] {m}"))
    result.problems[:0] = campaign.problems
    print(diagnosis_summary(result))
    document = result.to_json()
    if args.json:
        write_atomically(args.json, lambda p: p.write_text(json.dumps(document, indent=1)))
        print(f"json:   {args.json}")
    if args.report:
        progress("writing the report")
        # the page's figures need matplotlib; the summary and the JSON do not
        from landing_gear_sim.report.diagnosis import write_diagnosis_report

        page = write_diagnosis_report(result, args.report)
        print(f"report: {page}")
    if args.output:
        write_atomically(args.output, lambda path: write_extended_model(result, path))
        print(f"extended model: {args.output}")
    print(f"diagnosed {len(campaign.runs)} runs in {time.perf_counter() - started:.1f} s")
    return 0


def cmd_metrics(args: argparse.Namespace) -> int:
    from antiskid.metrics import (
        braking_metrics,
        metrics_table,
        stops,
        unconfirmed_locks,
        unfinished,
    )
    from landing_gear_sim.calibration.plausibility import check_units
    from landing_gear_sim.calibration.runs import classify_all
    from msg_tools.io import at_one_rate

    check_outputs(files=[args.json, args.plot])
    rig = params_of(args)
    run = at_one_rate(read_one(args.run, mapping_of(args)))  # its statistics by time
    parts = stops(run)
    # a unit within every range (a wheel in rpm: slip −7.8 accepted) named as identify does
    check_units(classify_all(parts), rig)
    rows = {part.name: braking_metrics(part, rig) for part in parts}
    for note in filter(None, (said(part, rig) for part in parts
                              for said in (unfinished, unconfirmed_locks))):
        progress(f"note: {note}")
    print(metrics_table(rows))
    if len(parts) == 1:
        _write_braking_outputs(args, run, rig, rows[run.name])
        return 0
    if args.json:
        _write_json(args.json, {"stops": [{"name": name, **m.to_dict()}
                                          for name, m in rows.items()]})
        print(f"  json: {args.json} ({len(parts)} stops)")
    if args.plot:
        print(f"  plot: not drawn for a log of {len(parts)} stops (cut the log to one stop)")
    return 0


def cmd_antiskid(args: argparse.Namespace) -> int:
    from antiskid.closed_loop import (
        closed_loop,
        constant_pressure_baseline,
        make_controller,
        with_surface,
    )
    from antiskid.metrics import braking_metrics, efficiency_against_distance, metrics_table
    from msg_tools.csv_io import write_csv

    check_outputs(files=[args.output, args.json, args.plot])
    rig = with_surface(params_of(args), args.surface)
    settings = dict(parse_assignment(text) for text in args.setting)
    step_s = 1.0 / (args.rate or rig.number(K.SIMULATION_OUTPUT_RATE_HZ))
    controller = make_controller(args.controller, rig, step_s, settings)
    progress(f"{args.controller} controller on the {args.surface} surface, closed loop")
    run = closed_loop(rig, controller, args.rate or 0.0).to_run()
    run = dataclasses.replace(run, name=f"{args.controller}_{args.surface}")
    metrics = braking_metrics(run, rig)
    progress("constant-pressure baseline just below the skid pressure (bisection)")
    pressure, baseline = constant_pressure_baseline(rig)
    rows = {run.name: metrics,
            f"constant {pressure / PA_PER_BAR:.1f} bar": braking_metrics(baseline.to_run(), rig)}
    print(metrics_table(rows))
    if (why := efficiency_against_distance(rows)) is not None:
        print(why)
    if metrics.cycling_near_gear_walk:
        print(f"WARNING: pressure cycles at {metrics.cycling_frequency_hz:.1f} Hz, near the "
              f"gear-walk resonance ({metrics.gear_walk_frequency_hz:.1f} Hz)")
    output = args.output or Path("out") / f"{run.name}.csv"
    output.parent.mkdir(parents=True, exist_ok=True)
    write_csv(run, output)
    print(f"  csv:  {output}")
    _write_braking_outputs(args, run, rig, metrics, output.with_suffix(".png"))
    return 0


def _write_json(path: Path, document: object) -> None:
    import json

    write_atomically(path, lambda p: p.write_text(json.dumps(document, indent=1)))


def _write_braking_outputs(args: argparse.Namespace, run: Run, rig: RigParameters,
                           metrics: BrakingMetrics, default_plot: Path | None = None) -> None:
    if args.json:
        _write_json(args.json, metrics.to_dict())
        print(f"  json: {args.json}")
    plot = args.plot or default_plot
    if plot is not None:
        from antiskid.metrics import slip_from, speeds_m_s
        from landing_gear_sim.report.braking import plot_braking  # matplotlib: 1 s to start

        vehicle, wheel = speeds_m_s(run, rig)
        path = plot_braking(run, slip_from(vehicle, wheel), wheel, vehicle, metrics, plot)
        print(f"  plot: {path}")


