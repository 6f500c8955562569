"""The CLI guides (issue 63, item 6): diagnose's help lists what a verdict can be and what a
diagnosis may start without; the missing-columns error names the way out; metrics' headers
carry their units, and a longer stop at a higher efficiency is explained where it shows."""

from __future__ import annotations

import pytest

from landing_gear_sim.cli import main
from landing_gear_sim.diagnosis.catalogue import CATALOGUE
from landing_gear_sim.diagnosis.families import REGISTRY
from landing_gear_sim.diagnosis.start import REMOVABLE


def test_diagnose_help_lists_the_verdict_kinds_and_the_without_elements(capsys):
    with pytest.raises(SystemExit):
        main(["diagnose", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    for kind in (*CATALOGUE, "discovered", "unexplained", "none", "inconclusive",
                 *{f.reports.split("+")[0] for f in REGISTRY}, *REMOVABLE):
        assert kind in out, kind


def test_the_missing_columns_error_names_the_mapping_and_the_contract(tmp_path, capsys):
    path = tmp_path / "run.csv"
    path.write_text("t,i,p\n" + "".join(f"{k / 1000},{0.5},{10}\n" for k in range(300)))
    assert main(["metrics", str(path)]) == 2
    err = capsys.readouterr().err
    assert "--mapping" in err and "docs/data-contract.md" in err, err


def test_metrics_headers_carry_their_units(tmp_path, capsys):
    path = tmp_path / "run.csv"
    assert main(["simulate", "--pressure-bar", "20", "--no-plot", "-o", str(path)]) == 0
    capsys.readouterr()
    assert main(["metrics", str(path)]) == 0
    header = capsys.readouterr().out.splitlines()[0]
    for unit in ("[m]", "[s]", "[m/s²]", "[Hz]"):
        assert unit in header, header


def test_a_longer_stop_at_a_higher_efficiency_is_explained(tmp_path, capsys):
    """Issue 63: the threshold controller showed a higher efficiency and deceleration yet a
    longer stop than the constant-pressure baseline, and nothing on the screen said why."""
    assert main(["antiskid", "--controller", "threshold", "--surface", "wet", "-o",
                 str(tmp_path / "run.csv")]) == 0
    out = capsys.readouterr().out
    rows = [line.split() for line in out.splitlines() if line.startswith(("threshold",
                                                                          "constant"))]
    shift = [0 if r[0] == "threshold_wet" else 2 for r in rows]  # "constant 36.9 bar"
    efficiency = [float(r[1 + k]) for r, k in zip(rows, shift, strict=True)]
    stop = [float(r[3 + k]) for r, k in zip(rows, shift, strict=True)]
    paradox = (efficiency[0] - efficiency[1]) * (stop[0] - stop[1]) > 0
    said = [line for line in out.splitlines() if "averaged over" in line]
    assert bool(said) == paradox, out
