"""What a page or a terminal says only when it means something (issue 64, "noise on the
page"): a check of a channel the log never had is not made, 0 ± 0 is no infinite-σ
deviation, and a reader's library's warning is a note of the run, not a line on the
terminal."""

from __future__ import annotations

import warnings

import numpy as np

from landing_gear_sim.calibration.runs import classified
from landing_gear_sim.diagnosis.consistency import under_floor
from landing_gear_sim.diagnosis.equations.load_cell import no_contact
from landing_gear_sim.diagnosis.relations import Check, Relation
from landing_gear_sim.model import scenario as sc
from landing_gear_sim.model.integrate import simulate
from msg_tools.contract import CSV_COLUMNS, CSV_SCALE_TO_SI, CSV_TO_FIELD
from msg_tools.io import read_run


def test_zero_plus_minus_zero_is_no_deviation():
    """'no contact ⇒ no load … +0 N ± 0 (infσ)' had stood for channels a three-column log
    never had."""
    nothing = Check(Relation.NO_CONTACT, "valve_step", "whole run, F_z", 0.0, 0.0, 150.0, "N")
    assert nothing.z == 0.0 and not nothing.violated
    assert under_floor([nothing]) == []


def test_a_three_column_valve_log_has_no_load_cell_checks(reference, tmp_path):
    result = simulate(reference, sc.actuator_test(reference, sc.constant(0.5), 3.0, "valve"))
    logged = result.to_run(noise=3)
    table = {c: getattr(logged, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS[:3]}
    path = tmp_path / "valve.csv"
    path.write_text(",".join(table) + "\n" + "\n".join(
        ",".join(f"{table[c][k]:.9g}" for c in table) for k in range(len(logged))) + "\n")
    assert no_contact(classified(read_run(path)), reference) == []


def test_a_readers_library_warning_is_a_note_of_the_run(tmp_path, reference, monkeypatch):
    """scipy's MatReadWarning had reached the user's terminal."""
    import scipy.io

    result = simulate(reference, sc.actuator_test(reference, sc.constant(0.5), 1.0, "valve"))
    run = result.to_run()
    vectors = {c: getattr(run, CSV_TO_FIELD[c]) / CSV_SCALE_TO_SI[c] for c in CSV_COLUMNS}
    path = tmp_path / "valve.mat"
    scipy.io.savemat(path, vectors)
    loadmat = scipy.io.loadmat

    def warning_loadmat(*args, **kwargs):
        warnings.warn("Duplicate variable name 'x' in stream", scipy.io.matlab.MatReadWarning,
                      stacklevel=2)
        return loadmat(*args, **kwargs)

    monkeypatch.setattr(scipy.io, "loadmat", warning_loadmat)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = read_run(path)
    assert any("Duplicate variable name" in n for n in again.notes), again.notes
    assert np.allclose(again.pressure_pa, run.pressure_pa)
