"""The verdict guard of a refactor: what the diagnosis answers on a fixed set of campaigns,
kept before a change and compared after it.

Run: ``python bench/verdicts.py --save out/verdicts/before.json`` on the code before, then
``python bench/verdicts.py --against out/verdicts/before.json`` after each step. A
campaign's answer is its verdict and, per finding, its cause (family, equation) and key
parameters with their σ. After a step every verdict and every finding's cause must be the
same, and each parameter must lie within its σ of the kept value (the larger of the two
σ); the command lists every difference and exits 1 when there is one. It answers for the
checkout it stands in, and refuses to run on another's code: from a worktree, run it with
``PYTHONPATH`` set to the worktree.

The campaigns (``--sets``, default all):

- ``independent``, ``unseen``: ``../shared/data`` (another simulator's campaigns, with the
  ``without`` of their truth and the datasheet they carry);
- ``bench``: ``bench/diagnose.py``'s generated campaigns and the two example campaigns;
- ``outside``: the own outside-the-library sweep (``bench/detection.py``'s OUTSIDE causes,
  its seeds, logged as its random loggers log).

Every campaign's truth is known (independent, unseen, outside; a bench campaign's is the
cause its case hides, with the rig written beside its runs, or the effect an example
campaign's ``generating-parameters.json`` holds). Each answer is also judged by it, as
``detection.py`` judges it, and the run ends with how many are right, after and kept: two
answers that differ may both be right, or the change may have cost a right one.
A kept file written before the answers carried what a judgement needs (a finding's held-out
gain, the final valve's ω_n and ζ) is judged only where it does not need them.

Generated campaigns are written once under ``--campaigns`` (default
``out/verdicts/campaigns``) and read from there afterwards: the data stay those the kept
answers were made on, whatever the change does to the generator. Each answer is written to
the output file as it comes, so a stopped run started again does only the rest.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path

import detection
import diagnose as bench_diagnose
import independent
import numpy as np

from landing_gear_sim.calibration.campaign import GENERATING_FILE, generate_campaign, rig_like
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.model import keys as K
from landing_gear_sim.model.parameters import load_parameters
from msg_tools.io import read_runs

SETS = ("independent", "unseen", "bench", "outside")
Answer = dict[str, object]
CHECKOUT = Path(__file__).resolve().parents[1]


def imported_from() -> Path:
    """The checkout whose ``landing_gear_sim`` this process runs."""
    return Path(diagnose.__code__.co_filename).resolve().parents[2]


@dataclass(frozen=True)
class Campaign:
    """One campaign of the guard: where its runs are, what to start without, its datasheet
    (None: the reference rig's), and how to write it when it is generated."""

    key: str
    folder: Path
    without: tuple[str, ...] = ()
    datasheet: Path | None = None
    make: Callable[[Path], None] | None = None
    right: Callable[[Answer], bool | None] | None = None  # by its truth; None: none known


def _shared(kind: str) -> Iterator[Campaign]:
    folder = independent.FOLDER if kind == "independent" else independent.UNSEEN
    for path in independent.campaigns(folder):
        want = independent.expected(path) if kind == "independent" else None
        yield Campaign(f"{kind}/{path.name}", path, want.without if want else (),
                       independent.datasheet_of(path), right=_truth(path, want))


def _truth(path: Path, want: independent.Expected | None) -> Callable[[Answer], bool | None]:
    """How a shared campaign's answer is judged, as ``detection.py`` judges it: its cause
    and key parameters (an independent campaign's ``want``), its effect discovered in its
    equation (unseen), or another rig's truth (an unseen campaign with a datasheet)."""
    if want is not None:
        return lambda answer: independent.judge(answer, want).ok
    equation = independent.unseen_equation(path)
    if equation is not None:
        return lambda answer: independent.judge_unseen(answer, equation)[0]

    def datasheet_right(answer: Answer) -> bool | None:
        valve = answer.get("valve")
        if not isinstance(valve, dict):
            return None
        return independent.judge_datasheet(answer, valve["natural_frequency_hz"],
                                           valve["damping_ratio"], path)[0]
    return datasheet_right


def _bench(root: Path) -> Iterator[Campaign]:
    """``bench/diagnose.py``'s campaigns, each judged by its truth: a generated one by the
    cause its case hides and the rig written beside its runs, an example campaign by the
    effect its ``generating-parameters.json`` holds."""
    base = load_parameters()
    for i, (name, case) in enumerate(bench_diagnose.CASES.items()):
        def make(folder: Path, i: int = i, case: bench_diagnose.Case = case) -> None:
            rig = rig_like(base, np.random.default_rng(500 + i)).replace(case.effect,
                                                                         "hidden effect")
            generate_campaign(folder, rig, 500 + i, case.runs)
        slug = name.replace(" ", "_").replace(",", "")
        folder = root / "bench" / slug
        yield Campaign(f"bench/{slug}", folder, case.without, None, make,
                       partial(_generated_right, cause=case.cause, folder=folder))
    for name in ("campaign_v1", "campaign_v2"):
        folder = bench_diagnose.SHARED / name
        if folder.is_dir():
            want = independent.expected_of(json.loads(
                (folder / "generating-parameters.json").read_text(encoding="utf-8")))
            yield Campaign(f"bench/{name}", folder,
                           right=lambda answer, want=want: independent.judge(answer, want).ok)


def _generated_right(answer: Answer, cause: str | None, folder: Path) -> bool:
    """A generated campaign's answer by the rig that made it (its truth, written beside its
    runs)."""
    rig = load_parameters([folder / GENERATING_FILE])
    return detection.catalogue_right(answer, cause, rig)


def _outside(root: Path, seed: int = 1000, per_cause: int = 3) -> Iterator[Campaign]:
    """detection.py's plan (its default causes and seeds), OUTSIDE causes only; a cause's
    campaigns kept under ``root`` keep their seeds (a family added to the registry shifts
    the plan's seeds, and the guard compares the same campaigns)."""
    causes = [*detection.CASES, *detection.FAMILIES, *detection.OUTSIDE]
    for i, cause in enumerate(causes):
        if cause not in detection.OUTSIDE:
            continue
        kept = sorted(int(f.name.rsplit("-", 1)[1])
                      for f in (root / "outside").glob(f"{cause}-*") if f.is_dir())
        for number in kept or [seed + 17 * i + j for j in range(per_cause)]:

            def make(folder: Path, cause: str = cause, number: int = number) -> None:
                _write_outside(folder, cause, number)
            yield Campaign(f"outside/{cause}-{number}", root / "outside" / f"{cause}-{number}",
                           make=make, right=partial(_outside_right, cause=cause))


def _outside_right(answer: Answer, cause: str) -> bool | None:
    findings = answer["findings"]
    assert isinstance(findings, list)
    if findings and "held_out_delta" not in findings[0]:
        return None  # kept before the answers carried it
    return detection.outside_right(answer, detection.OUTSIDE[cause][0])


def _write_outside(folder: Path, cause: str, seed: int) -> None:
    """The campaign detection.py diagnoses for (cause, seed) with --logger-realities."""
    datasheet = load_parameters()
    rng = np.random.default_rng(seed)
    rig = rig_like(datasheet, rng)
    rig = rig.replace(detection.OUTSIDE[cause][1](rng, datasheet), "hidden effect")
    logger = detection.random_logger(np.random.default_rng([seed, 2]))
    generate_campaign(folder, rig, seed, logger=logger)


def plan(sets: list[str], root: Path) -> list[Campaign]:
    chosen: list[Campaign] = []
    for kind in sets:
        chosen += list(_shared(kind) if kind in ("independent", "unseen") else
                       _bench(root) if kind == "bench" else _outside(root))
    return chosen


def answer(campaign: Campaign) -> Answer:
    """The diagnosis' verdict, and each finding's cause with its parameters and σ."""
    if campaign.make is not None and not (campaign.folder / GENERATING_FILE).is_file():
        campaign.make(campaign.folder)
    sheet = campaign.datasheet
    start = load_parameters([sheet], over_reference=True) if sheet else load_parameters()
    result = diagnose(read_runs([campaign.folder]).runs, start,
                      without=list(campaign.without))
    return {"verdict": result.verdict,
            "findings": [{"cause": f.cause, "family": f.family, "equation": f.equation,
                          "term": f.term, "parameters": dict(f.parameters),
                          "uncertainty": dict(f.std), "held_out_delta": f.held_out}
                         for f in result.findings],
            # what the truth's judges read beside the findings, not compared
            "valve": {"natural_frequency_hz": result.extended.number(
                          K.ACTUATOR_NATURAL_FREQUENCY_HZ),
                      "damping_ratio": result.extended.number(K.ACTUATOR_DAMPING_RATIO)},
            # what the campaign leaves open: said beside the verdict, not compared
            "alike": [list(group.names) for group in result.alike],
            "next_run": None if result.next_run is None else result.next_run.proposal.options}


def differences(before: Answer, after: Answer) -> list[str]:
    """How ``after`` differs from ``before``: verdict, causes, parameters beyond σ."""
    if before["verdict"] != after["verdict"]:
        return [f"verdict {before['verdict']} -> {after['verdict']}"]
    was, now = before["findings"], after["findings"]
    assert isinstance(was, list) and isinstance(now, list)
    names = [[(f["cause"], f["family"], f["equation"]) for f in x] for x in (was, now)]
    if names[0] != names[1]:
        return [f"findings {names[0]} -> {names[1]}"]
    found = []
    for old, new in zip(was, now, strict=True):
        for name, value in old["parameters"].items():
            moved = new["parameters"].get(name, math.nan)
            sigma = max(_sigma(old, name), _sigma(new, name))
            if not abs(moved - value) <= sigma:
                found.append(f"{old['cause']}.{name} {value:.6g} -> {moved:.6g} "
                             f"(σ {sigma:.3g})")
    return found


def _sigma(finding: dict, name: str) -> float:
    value = finding["uncertainty"].get(name)
    return float(value) if value is not None and math.isfinite(value) else 0.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--save", type=Path, help="write the answers here")
    what.add_argument("--against", type=Path, help="compare with answers kept here")
    parser.add_argument("--sets", default=",".join(SETS), help=f"of {', '.join(SETS)}")
    parser.add_argument("--only", default="", help="only campaigns whose key contains this")
    parser.add_argument("--campaigns", type=Path, default=Path("out/verdicts/campaigns"))
    parser.add_argument("--output", type=Path,
                        help="with --against: where the answers after go (default: beside the "
                             "kept ones, *.after.json); a run started again resumes it")
    args = parser.parse_args()
    unknown = set(args.sets.split(",")) - set(SETS)
    if unknown:
        parser.error(f"--sets: unknown {', '.join(sorted(unknown))}")
    if imported_from() != CHECKOUT:
        # run from a worktree, a script's path is its bench/ folder and the editable install
        # gives the main checkout's code: the guard would answer for another change
        parser.error(f"the diagnosis imported is {imported_from()}'s, not this checkout's "
                     f"({CHECKOUT}): run it with PYTHONPATH={CHECKOUT}")
    kept = json.loads(args.against.read_text(encoding="utf-8")) if args.against else {}
    output = args.save or args.output or args.against.with_suffix(".after.json")
    done = json.loads(output.read_text(encoding="utf-8")) if output.is_file() else {}
    found = 0
    right = Right()
    for campaign in plan(args.sets.split(","), args.campaigns):
        if args.only not in campaign.key:
            continue
        if args.against and campaign.key not in kept:
            print(f"{campaign.key}: not kept, skipped", file=sys.stderr)
            continue
        if campaign.key not in done:
            started = time.perf_counter()
            done[campaign.key] = answer(campaign)
            done[campaign.key]["seconds"] = round(time.perf_counter() - started, 1)
            output.parent.mkdir(parents=True, exist_ok=True)
            output.write_text(json.dumps(done, indent=1), encoding="utf-8")
        now = done[campaign.key]
        shown = " ".join(f"{f['cause']}({f['family'] or f['equation']})"
                         for f in now["findings"])
        line = f"{campaign.key:50s} {now['verdict']:12s} {shown}" + "".join(
            f" [{' or '.join(group)}]" for group in now.get("alike", []))
        right.add(campaign, now, kept.get(campaign.key))
        if args.against:
            diff = differences(kept[campaign.key], now)
            found += bool(diff)
            line += "  SAME" if not diff else "  DIFFERS: " + "; ".join(diff)
        print(line, flush=True)
    print(right.summary(bool(args.against)))
    if args.against:
        print(f"{found} campaigns differ; answers in {output}")
    return 1 if found else 0


@dataclass
class Right:
    """How many answers are right by their campaign's truth, now and kept, and which
    changed: counted where both are judged, so the two counts compare."""

    judged: int = 0
    now: int = 0
    kept: int = 0
    changed: list[str] = field(default_factory=list)

    def add(self, campaign: Campaign, now: Answer, kept: Answer | None) -> None:
        if campaign.right is None:
            return
        was = campaign.right(kept) if kept is not None else None
        is_right = campaign.right(now)
        if is_right is None or (kept is not None and was is None):
            return
        self.judged += 1
        self.now += is_right
        self.kept += bool(was)
        if kept is not None and was != is_right:
            self.changed.append(f"{campaign.key} ({'now right' if is_right else 'now wrong'})")

    def summary(self, against: bool) -> str:
        line = f"right by the truth: {self.now}/{self.judged}"
        if against:
            line += (f" (kept: {self.kept}/{self.judged})"
                     + "".join(f"; {key}" for key in self.changed))
        return line


if __name__ == "__main__":
    sys.exit(main())
