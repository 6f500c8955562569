"""``montecarlo``: closed-loop stops over dispersions, on Dask."""

from __future__ import annotations

import argparse
import csv
import json
from pathlib import Path
from typing import Any

from landing_gear_sim.cli.common import (
    add_params_arguments,
    check_outputs,
    params_of,
    progress,
    write_atomically,
)
from landing_gear_sim.cli.fleet import add_engine_arguments
from landing_gear_sim.errors import LandingGearSimError
from landing_gear_sim.model.parameters import RigParameters


def register(sub: argparse._SubParsersAction) -> None:
    """Add ``montecarlo`` to the ``landing-gear-sim`` parser."""
    mc = sub.add_parser("montecarlo", help="closed-loop stops over surfaces, speeds, loads and "
                        "identified parameters (Dask): distributions, worst cases to replay")
    mc.add_argument("--controller", choices=["threshold", "slip"], required=True,
                    help="anti-skid logic to test")
    add_params_arguments(mc, without=False)
    mc.add_argument("--cases", type=int, default=200, help="stops to simulate (default 200)")
    mc.add_argument("--seed", type=int, default=1, help="the same seed gives the same cases")
    mc.add_argument("--surfaces", nargs="+", default=None, metavar="SURFACE",
                    help="drawn among dry wet snow jump (jump: dry, then wet or snow "
                    "mid-stop; default all four)")
    mc.add_argument("--speed", type=float, nargs=2, default=(50.0, 70.0),
                    metavar=("LOW", "HIGH"), help="entry speed range [m/s] (default 50 70)")
    mc.add_argument("--load", type=float, nargs=2, default=(0.85, 1.15),
                    metavar=("LOW", "HIGH"), help="static load factor range (default 0.85 "
                    "1.15)")
    mc.add_argument("--evidence", type=Path, help="identification evidence whose 1-σ are "
                    "drawn (default: <config>.identification.json beside the last --config)")
    mc.add_argument("--no-parameter-dispersion", action="store_true",
                    help="keep the parameters at their values (surfaces, speeds, loads only)")
    mc.add_argument("--worst", type=int, default=5,
                    help="worst cases written as replayable runs (default 5)")
    mc.add_argument("-o", "--output", type=Path, default=Path("out/montecarlo"),
                    help="folder: cases.csv, summary.json, montecarlo.png, worst/, and the "
                    "journal that lets a stopped run resume (default out/montecarlo)")
    add_engine_arguments(mc)
    mc.set_defaults(func=cmd_montecarlo)


def _sigma(args: argparse.Namespace) -> tuple[tuple[str, float], ...]:
    from landing_gear_sim.campaigns.montecarlo import identification_sigma

    if args.no_parameter_dispersion:
        return ()
    evidence = args.evidence
    if evidence is None and args.config:
        evidence = args.config[-1].with_suffix(".identification.json")
        if not evidence.exists():
            progress(f"no identification evidence at {evidence}: parameters not dispersed")
            return ()
    if evidence is None:
        return ()
    try:
        document = json.loads(evidence.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise LandingGearSimError(f"{evidence}: cannot read ({exc})") from None
    sigma = identification_sigma(document)
    progress(f"{len(sigma)} identified parameters drawn from their 1-σ ({evidence})")
    return sigma


def cmd_montecarlo(args: argparse.Namespace) -> int:
    from landing_gear_sim.campaigns.engine import Task, client, run_tasks
    from landing_gear_sim.campaigns.montecarlo import SURFACE_KINDS, Plan, chunk_task, chunks

    check_outputs(folders=[args.output])
    base = params_of(args)
    plan = Plan(args.controller, {}, args.seed, args.cases,
                tuple(args.surfaces or SURFACE_KINDS), tuple(args.speed), tuple(args.load),
                sigma=_sigma(args))
    tag = plan.fingerprint(base)
    tasks = [Task(f"{tag}-{i[0]:06d}", chunk_task, (base, plan, i)) for i in chunks(plan)]
    journal = args.output / "journal.jsonl"
    progress(f"{plan.cases} {plan.controller} stops in {len(tasks)} tasks; results go to "
             f"{journal} as they finish")
    with client(args.scheduler, args.workers) as engine:
        results = run_tasks(tasks, journal, engine, progress)
    rows = sorted((row for t in tasks if t.key in results for row in results[t.key]["cases"]),
                  key=lambda r: r["case"])
    _write_outputs(base, plan, rows, args.output, args.worst)
    missing = plan.cases - len(rows)
    if missing:
        progress(f"{missing} cases did not run; run the same command again to finish them")
    return 0 if not missing else 1


def _write_outputs(base: RigParameters, plan: Any, rows: list[dict[str, Any]], folder: Path,
                   worst: int) -> None:
    from landing_gear_sim.campaigns.montecarlo import summary, worst_cases
    from landing_gear_sim.report.montecarlo import plot_montecarlo

    numbers = summary(rows)
    write_atomically(folder / "cases.csv", lambda p: _write_csv(rows, p))
    write_atomically(folder / "summary.json",
                     lambda p: p.write_text(json.dumps(numbers, indent=1)))
    figure = plot_montecarlo(rows, numbers, folder / "montecarlo.png") if rows else None
    replays = _write_worst(base, plan, worst_cases(rows, worst), folder / "worst")
    _print_summary(numbers, folder, figure, replays)


def _write_csv(rows: list[dict[str, Any]], path: Path) -> None:
    columns = list(dict.fromkeys(key for row in rows for key in row))
    with path.open("w", newline="", encoding="utf-8") as out:
        writer = csv.DictWriter(out, columns)
        writer.writeheader()
        writer.writerows(rows)


def _write_worst(base: RigParameters, plan: Any, rows: list[dict[str, Any]],
                 folder: Path) -> list[str]:
    """Each worst case as a contract run and the parameter set it ran on: ``rig --replay``
    drives the graph with its current and gives the same stop."""
    from landing_gear_sim.campaigns.montecarlo import draw_case, simulate_case
    from msg_tools.csv_io import write_csv

    commands = []
    folder.mkdir(parents=True, exist_ok=True)
    for row in rows:
        case = draw_case(base, plan, row["case"])
        result = simulate_case(base, plan, case)
        run_path, params_path = folder / f"{case.name}.csv", folder / f"{case.name}.yaml"
        write_csv(result.to_run(), run_path)
        write_atomically(params_path, result.params.to_yaml)
        commands.append(f"landing-gear-sim rig --replay {run_path} --config {params_path}")
    return commands


def _print_summary(numbers: dict[str, Any], folder: Path, figure: Path | None,
                   replays: list[str]) -> None:
    print(f"{numbers['cases']} stops ({numbers['failed']} without braking metrics)")
    print(f"{'surface':14s} {'n':>5s} {'efficiency p5/p50':>18s} {'stop m p50/p95':>15s} "
          f"{'lock rate':>9s}")
    for surface, d in [("all", numbers), *numbers["by_surface"].items()]:
        if not d.get("n"):
            continue
        eff, dist = d["braking_efficiency"], d["stopping_distance_m"]
        print(f"{surface:14s} {d['n']:5d} {eff['p5']:8.3f} /{eff['p50']:6.3f}   "
              f"{dist['p50']:6.0f} /{dist['p95']:6.0f} {100 * d['lock_rate']:8.1f} %")
    print(f"cases:   {folder / 'cases.csv'}\nsummary: {folder / 'summary.json'}")
    if figure is not None:
        print(f"plot:    {figure}")
    for command in replays:
        print(f"replay:  {command}")
