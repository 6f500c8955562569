"""The fits on forward differences against the fits on the plant's own derivatives (issue 61,
``differences.MODEL_DERIVATIVES``), campaign by campaign: each path's verdict and findings,
the final model's cost over the whole campaign, and the diagnosis's time.

Run: ``python bench/jacobians.py [CAMPAIGN ...]`` (a campaign folder, with its
``datasheet.yaml`` when it has one; by default ``../shared/data``'s campaign_v1 and U01, when
present). Each path diagnoses in a fresh interpreter of this
checkout, the plant's derivatives compiled before the clock starts. The cost is what the
fits minimise (``diagnosis.objective.scaled_error``), taken over every run and channel:
Σ (model − log)² / σ², σ each channel's logger noise read from the run. Where the two
paths answer differently, the lower cost says which ended on the better optimum; "on/off"
is the cost with the plant's derivatives over the cost with differences.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
SHARED = HERE.parent / "shared" / "data"
DEFAULT = (SHARED / "campaign_v1", SHARED / "unseen" / "U01_tyre_shape")
MEASURE = """
import json, sys, time
from pathlib import Path
import numpy as np
from landing_gear_sim.calibration import differences
differences.MODEL_DERIVATIVES = sys.argv[2] == "on"
from landing_gear_sim.calibration.measured import CHANNELS, channels_of, simulate_all
from landing_gear_sim.calibration.runs import classify_all
from landing_gear_sim.diagnosis.catalogue import noise_scales
from landing_gear_sim.diagnosis.diagnose import diagnose
from landing_gear_sim.diagnosis.objective import scaled_error
from landing_gear_sim.model.parameters import load_parameters
from landing_gear_sim.model.sensitivity import prepare_kernels
from msg_tools.io import read_runs
folder = Path(sys.argv[1])
sheet = folder / "datasheet.yaml"
base = load_parameters([sheet], over_reference=True) if sheet.is_file() else load_parameters()
runs = read_runs([folder]).runs
simulate_all(runs, base)
if differences.MODEL_DERIVATIVES:
    prepare_kernels(base)
start = time.perf_counter()
result = diagnose(runs, base)
seconds = time.perf_counter() - start
classified = classify_all(runs)
scales = noise_scales(classified, tuple(CHANNELS))
def cost(params):
    return sum(float(np.sum(scaled_error([run], [model], channels_of(run), scales) ** 2))
               for run, model in zip(classified, simulate_all(classified, params), strict=True))
print(json.dumps({"verdict": result.verdict, "seconds": seconds,
                  "cost": cost(result.extended), "calibrated": cost(result.calibrated),
                  "findings": [[f.cause, f.family, f.term, f.delta_bic, f.held_out]
                               for f in result.findings]}, ensure_ascii=False))
"""


def _diagnosed(folder: Path, derivatives: str) -> dict:
    """One diagnosis of ``folder`` with the plant's derivatives ``on`` or ``off``."""
    env = dict(os.environ, PYTHONPATH=str(HERE))
    done = subprocess.run([sys.executable, "-c", MEASURE, str(folder.resolve()), derivatives],
                          env=env, capture_output=True, text=True, cwd=tempfile.gettempdir())
    if done.returncode != 0:
        sys.exit(f"{folder} with the plant's derivatives {derivatives}: the diagnosis failed:\n"
                 + "\n".join(done.stderr.strip().splitlines()[-5:]))
    return json.loads(done.stdout.strip().splitlines()[-1])


def _findings(answer: dict) -> str:
    return "; ".join(f"{cause} {family} {term} (ΔBIC {bic}, held out {held})".replace("  ", " ")
                     for cause, family, term, bic, held in answer["findings"]) or "-"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("campaigns", nargs="*", type=Path,
                        default=[c for c in DEFAULT if c.is_dir()])
    args = parser.parse_args()
    if not args.campaigns:
        parser.error("no campaign given, and ../shared/data has none of the defaults")
    print("campaign: each path's verdict, time, final cost (Σ (residual/noise)² over every "
          "run), then the cost on/off and the findings")
    for folder in args.campaigns:
        off, on = _diagnosed(folder, "off"), _diagnosed(folder, "on")
        same = "same verdict" if off["verdict"] == on["verdict"] else "verdicts differ"
        print(f"{folder.name}: {same}, cost on/off {on['cost'] / off['cost']:.3f}", flush=True)
        for name, answer in (("differences", off), ("derivatives", on)):
            print(f"  {name:12s} {answer['verdict']:14s} {answer['seconds']:6.1f} s "
                  f"cost {answer['cost']:.4g}  {_findings(answer)}", flush=True)


if __name__ == "__main__":
    main()
