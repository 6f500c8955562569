"""The commands over many campaigns, on Dask: history."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from landing_gear_sim.cli.common import (
    InputPath,
    add_params_arguments,
    check_outputs,
    params_of,
    progress,
)


def register(sub: argparse._SubParsersAction) -> None:
    """Add the sub-commands of this module to the ``landing-gear-sim`` parser."""
    hist = sub.add_parser("history", help="identify and diagnose many campaigns (Dask); "
                          "parameter table, trends and steps over time")
    hist.add_argument("campaigns", type=InputPath, nargs="+", metavar="CAMPAIGN",
                      help="campaign folders, or folders of campaigns (one per sub-folder); "
                      "time order is the order of the folder names")
    add_params_arguments(hist, without=False)
    hist.add_argument("-o", "--output", type=Path, default=Path("out/history"),
                      help="folder: history.csv (+ .parquet), changes.json, plots, and the "
                      "journal that lets a stopped run resume (default out/history)")
    hist.add_argument("--no-diagnose", action="store_true",
                      help="identify only (faster: the parameter table and its trends)")
    add_engine_arguments(hist)
    hist.set_defaults(func=cmd_history)


def add_engine_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--scheduler", metavar="tcp://HOST:8786",
                        help="a running Dask scheduler (default: a local cluster, one worker "
                        "per core)")
    parser.add_argument("--workers", type=int, help="local cluster: worker processes")


def cmd_history(args: argparse.Namespace) -> int:
    from landing_gear_sim.campaigns.engine import Task, client, run_tasks
    from landing_gear_sim.campaigns.history import (
        campaign_folders,
        campaign_task,
        changes,
    )

    check_outputs(folders=[args.output])
    folders = campaign_folders(args.campaigns)
    base = params_of(args)
    diagnosis = not args.no_diagnose
    tasks = [Task(str(f.resolve()), campaign_task, (str(f.resolve()), base, diagnosis))
             for f in folders]
    journal = args.output / ("journal.jsonl" if diagnosis else "journal-identify.jsonl")
    progress(f"{len(tasks)} campaigns; results go to {journal} as they finish")
    with client(args.scheduler, args.workers) as engine:
        results = run_tasks(tasks, journal, engine, progress)
    rows = [results[t.key] for t in tasks if t.key in results]
    found = changes(rows)
    _write_outputs(rows, found, args.output)
    _print_summary(rows, found, args.output)
    missing = len(tasks) - len(rows)
    if missing:
        progress(f"{missing} campaigns failed to run; run the same command again to retry")
    return 0 if not missing and all(r["status"] == "ok" for r in rows) else 1


def _write_outputs(rows: list[dict[str, Any]], found: list[Any], folder: Path) -> None:
    from landing_gear_sim.campaigns.history import table_columns
    from landing_gear_sim.cli.common import write_atomically
    from landing_gear_sim.report.history import plot_history

    columns = table_columns(rows)
    write_atomically(folder / "history.csv", lambda p: _write_csv(columns, p))
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        progress("history.parquet not written: pyarrow is not installed "
                 "(pip install 'landing_gear_sim[formats]')")
    else:
        write_atomically(folder / "history.parquet",
                         lambda p: pq.write_table(pa.table(columns), p))
    from landing_gear_sim.campaigns.history import not_identified

    document = {"campaigns": rows, "changes": [c.to_json() for c in found],
                "not_identified": not_identified(rows)}
    write_atomically(folder / "changes.json",
                     lambda p: p.write_text(json.dumps(document, indent=1)))
    if rows:
        plot_history([r for r in rows if r["status"] == "ok"], found, folder / "plots")


def _write_csv(columns: dict[str, list[Any]], path: Path) -> None:
    import csv

    with path.open("w", newline="", encoding="utf-8") as out:
        writer = csv.writer(out)
        writer.writerow(columns)
        writer.writerows(zip(*columns.values(), strict=True))


def _print_summary(rows: list[dict[str, Any]], found: list[Any], folder: Path) -> None:
    for r in rows:
        state = r.get("verdict", "identified") if r["status"] == "ok" else \
            f"FAILED: {r['error']}"
        print(f"{r['campaign']:32s} {r.get('runs', 0):3d} runs  {state}")
    from landing_gear_sim.campaigns.history import not_identified

    print("changes over the campaigns:" if found else "no trend or step in any parameter")
    for c in found:
        print(f"  {c.describe()}")
    for key, campaigns in not_identified(rows).items():
        print(f"  {key}: not identified (held, σ = 0) in {', '.join(campaigns)}")
    print(f"table:  {folder / 'history.csv'}")
    print(f"plots:  {folder / 'plots'}")
