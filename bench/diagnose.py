"""Diagnosis benchmark: wall time, simulation passes and peak memory of ``diagnose`` on full
campaigns, against the code before measured in the same run.

Run: ``make bench`` (or ``python bench/diagnose.py [--against DIR]``). Full 8-run campaigns
(~150 s of 1 kHz data) made by the project's own rig generator: one without an extra effect,
one with an actuator delay, starting models without an element, and a partial campaign
(braking runs only); the example campaigns too when ``../shared/data`` is present. Each
diagnosis runs in a fresh interpreter of the checkout measured (compiled code loaded from
its cache, its first call excluded). "passes" is the diagnosis's time over one plain
simulation pass of the campaign (every run re-simulated with its measured input; the median
of three) in that same interpreter: a ratio that holds from machine to machine. With
``--against`` (the code before, a ``git worktree``) each campaign is diagnosed by both, one
after the other, and "faster" is the time before over the time now. "sim" counts the runs
the diagnosis simulated (in this process and its fits' processes), in whole-campaign
passes; "again" how many of those a parameter set had simulated already (issue 61: each
(parameters, run) once).

Targets (issue 61, a quiet 2-core machine): campaign_v1 ≤ 30 passes, every campaign ≤ 50,
peak memory no higher than before; the verdicts the same. With ``--busy N`` each campaign is
diagnosed once more beside N busy loops (processes spinning on a core each) and that time is
printed over the quiet one: campaign_v1 ≤ 2.5× its quiet time beside two.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path
from typing import NamedTuple

import numpy as np
from checkouts import is_checkout, measured_in
from stopping import busy_loops  # the same load as the stopping bench's

from landing_gear_sim.calibration.campaign import generate_campaign, rig_like
from landing_gear_sim.model.parameters import load_parameters

HERE = Path(__file__).resolve().parents[1]
SHARED = HERE.parent / "shared" / "data"
TARGET_V1_PASSES = 30
TARGET_ANY_PASSES = 50
TARGET_LOADED = 2.5  # campaign_v1 beside two busy loops, over its quiet time
BRAKING = ("brake_const_10bar", "brake_const_20bar", "brake_const_30bar", "brake_osc_low",
           "brake_osc_high")


class Case(NamedTuple):
    """A generated campaign of the bench: the effect hidden in its rig, the elements the
    starting model lacks, its runs (None: all), and the cause a right diagnosis names (None:
    none; the verdict guard judges the answers by it)."""

    effect: dict
    without: tuple[str, ...]
    runs: tuple[str, ...] | None
    cause: str | None


CASES: dict[str, Case] = {
    "no extra effect": Case({}, (), None, None),
    "actuator delay 6 ms": Case({"elements.actuator_delay": True, "actuator.delay_s": 0.006},
                                (), None, "actuator_delay"),
    "without load-dependent radius": Case({}, ("load_dependent_radius",), None,
                                          "load_dependent_radius"),
    "without friction curve": Case({}, ("friction_curve",), None, "friction_curve"),
    "without drag": Case({}, ("drag",), None, "drag"),
    "braking runs only, without gear walk": Case({}, ("gear_walk",), BRAKING, "gear_walk"),
}
# what a fresh interpreter of the checkout measured runs (the API it uses is the same before)
MEASURE = """
import hashlib, json, os, resource, sys, tempfile, time
from pathlib import Path
from landing_gear_sim.calibration import measured
from landing_gear_sim.calibration.measured import simulate_all
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.model.parameters import load_parameters
from msg_tools.io import read_campaign
runs = read_campaign(Path(sys.argv[1])).runs
base = load_parameters()
without = tuple(filter(None, sys.argv[2].split(",")))
simulate_all(runs, base)
try:  # the dual kernels loaded before the clock starts, where the fits use them
    from landing_gear_sim.calibration.differences import MODEL_DERIVATIVES
    from landing_gear_sim.model.sensitivity import prepare_kernels
    if MODEL_DERIVATIVES:
        prepare_kernels(base)
except ImportError:
    pass
# the median of three passes: one alone varied by 10 % from run to run, and the ratio with it
passes = []
for _ in range(3):
    start = time.perf_counter()
    simulate_all(runs, base)
    passes.append(time.perf_counter() - start)
one_pass = sorted(passes)[1]
# every simulation of a run with a parameter set, in this process and the forked fits':
# a line each, (parameters, run) hashed, appended to one file (O_APPEND: whole lines)
log = os.path.join(tempfile.mkdtemp(), "simulated")
plain = measured.simulate
def counted(params, scenario, *args, **kwargs):
    key = hashlib.blake2b(params.vector().tobytes() + scenario.name.encode()
                          + scenario.current_a.tobytes(), digest_size=12).hexdigest()
    fd = os.open(log, os.O_WRONLY | os.O_APPEND | os.O_CREAT)
    os.write(fd, (key + "\\n").encode())
    os.close(fd)
    return plain(params, scenario, *args, **kwargs)
measured.simulate = counted
start = time.perf_counter()
result = diagnose(runs, base, without=without)
elapsed = time.perf_counter() - start
keys = Path(log).read_text().split()
own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
worker = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
found = {k: v for f in result.findings[:1] for k, v in f.parameters.items()}
print(json.dumps({"checkout": str(Path(diagnose.__code__.co_filename).resolve().parents[2]),
                  "verdict": result.verdict, "seconds": elapsed, "pass_s": one_pass,
                  "peak_mb": own + 2 * worker, "found": found, "runs": len(runs),
                  "simulated": len(keys), "distinct": len(set(keys))}))
"""


def _measure(checkout: Path, folder: Path, without: tuple[str, ...]) -> dict:
    """One diagnosis of ``folder`` by ``checkout``'s code in a fresh interpreter."""
    return measured_in(checkout, MEASURE, str(folder), ",".join(without),
                       bench="bench/diagnose.py")


def _row(name: str, folder: Path, without: tuple[str, ...], before: Path | None,
         busy: int = 0) -> None:
    now = _measure(HERE, folder, without)
    passes = now["seconds"] / now["pass_s"]
    target = TARGET_V1_PASSES if name.startswith("campaign_v1") else TARGET_ANY_PASSES
    found = ", ".join(f"{k} = {v:.4g}" for k, v in now["found"].items())
    text = (f"{name:38s} {now['verdict']:16s} {now['seconds']:6.1f} s {passes:5.0f} "
            f"{target / passes:5.2f}x {now['peak_mb']:6.0f} MB {_simulated(now)}")
    if before is not None:
        then = _measure(before, folder, without)
        same = "same" if then["verdict"] == now["verdict"] else f"was {then['verdict']}"
        text += (f"  | before {then['seconds']:6.1f} s {then['seconds'] / then['pass_s']:5.0f}"
                 f" {then['seconds'] / now['seconds']:5.2f}x {then['peak_mb']:6.0f} MB "
                 f"{_simulated(then)} {same}")
    if busy:
        with busy_loops(busy):
            loaded = _measure(HERE, folder, without)
        text += (f"  | beside {busy} busy loops {loaded['seconds']:6.1f} s "
                 f"{loaded['seconds'] / now['seconds']:5.2f}x quiet")
    print(f"{text}  {found}", flush=True)


def _simulated(measured: dict) -> str:
    """The runs simulated, as whole-campaign passes, and those simulated again with the
    same parameters (issue 61: each (parameters, run) once)."""
    simulated, again = measured["simulated"], measured["simulated"] - measured["distinct"]
    return f"{simulated / measured['runs']:5.0f} sim {again:4d} again"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", type=Path, help="the code before (a checkout)")
    parser.add_argument("--busy", type=int, default=0, metavar="N",
                        help=f"diagnose each campaign again beside N busy loops (campaign_v1 "
                             f"beside 2: ≤ {TARGET_LOADED:g}x its quiet time)")
    args = parser.parse_args()
    if args.against and not is_checkout(args.against):
        parser.error(f"--against: {args.against} is not a checkout of the package")
    print("diagnose on full campaigns: time, passes (time over one simulation pass) and "
          "the passes' ratio to the target (> 1 beats it), peak memory, the runs simulated "
          "(in whole-campaign passes) and how many of them again with the same parameters"
          + ("; then the code before and how much faster now" if args.against else ""))
    base = load_parameters()
    for i, (name, case) in enumerate(CASES.items()):
        rig = rig_like(base, np.random.default_rng(500 + i)).replace(case.effect,
                                                                     "hidden effect")
        with tempfile.TemporaryDirectory() as folder:
            generate_campaign(Path(folder), rig, 500 + i, case.runs)
            _row(name, Path(folder), case.without, args.against, args.busy)
    for name in ("campaign_v1", "campaign_v2"):
        if (SHARED / name).is_dir():
            _row(f"{name} (example data)", SHARED / name, (), args.against, args.busy)


if __name__ == "__main__":
    main()
