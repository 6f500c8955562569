"""The landing-gear-sim command line, as a user runs it."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from landing_gear_sim.calibration.campaign import STANDARD_RUNS
from landing_gear_sim.cli import build_parser, main
from landing_gear_sim.model.parameters import load_parameters
from msg_tools.bag_read import read_bag
from msg_tools.csv_io import read_csv
from msg_tools.io import read_run


def test_simulate_writes_csv_bag_and_plot(tmp_path, capsys):
    csv, bag = tmp_path / "run.csv", tmp_path / "bag"
    assert main(["simulate", "--pressure-bar", "30", "-o", str(csv), "--bag", str(bag)]) == 0
    out = capsys.readouterr().out
    assert "stop speed reached" in out and "wheel locked 0.000 s" in out
    run = read_csv(csv)
    assert run.time_s[-1] > 10.0 and run.flywheel_speed_rad_s[0] == 60.0
    assert len(read_bag(bag)) == len(run)
    assert csv.with_suffix(".png").stat().st_size > 10_000


def test_simulate_reports_a_lock_at_45_bar(tmp_path, capsys):
    assert main(["simulate", "--pressure-bar", "45", "-o", str(tmp_path / "r.csv"),
                 "--no-plot"]) == 0
    locked_s = float(capsys.readouterr().out.split("wheel locked ")[1].split(" s")[0])
    assert locked_s > 1.0


def test_actuator_profile_runs_with_the_wheel_off(tmp_path):
    csv = tmp_path / "sweep.csv"
    assert main(["simulate", "--profile", "sweep", "--duration", "2", "-o", str(csv),
                 "--no-plot"]) == 0
    run = read_csv(csv)
    assert run.time_s[-1] == pytest.approx(1.999)
    assert run.wheel_speed_rad_s.max() == 0.0 and run.pressure_pa.max() > 20e5


def test_replaying_a_recorded_current_reproduces_the_run(tmp_path):
    first, second = tmp_path / "a.csv", tmp_path / "b.csv"
    assert main(["simulate", "--profile", "osc-high", "-o", str(first), "--no-plot"]) == 0
    assert main(["simulate", "--profile", "file", "--file", str(first), "-o", str(second),
                 "--no-plot"]) == 0
    a, b = read_csv(first), read_csv(second)
    n = min(len(a), len(b))
    assert abs(len(a) - len(b)) <= 1
    # the CSV's digits of the current are all the replay may lose: 1e-8 of 200 rad/s
    assert (abs(a.wheel_speed_rad_s[:n] - b.wheel_speed_rad_s[:n])).max() < 1e-8


@pytest.mark.parametrize(("argv", "fragment"), [
    (["simulate", "--pressure-bar", "99"], "outside the valve range"),
    (["simulate", "--set", "friction.theta1=-1"], "'friction.theta1' must not be negative"),
    (["simulate", "--set", "friction.thta1=1"], "did you mean 'friction.theta1'"),
    (["simulate", "--config", "/no/such.yaml"], "/no/such.yaml: no such file or folder"),
    (["simulate", "--profile", "file"], "--profile file needs --file"),
    (["simulate", "--profile", "file", "--file", "/no/run.csv"], "/no/run.csv: no such file"),
])
def test_bad_input_is_one_error_line_and_exit_2(argv, fragment, capsys, tmp_path):
    assert main([*argv, "-o", str(tmp_path / "x.csv")]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines[-1].startswith("landing-gear-sim: error:") and fragment in lines[-1]
    assert not any("Traceback" in line for line in lines)
    assert not (tmp_path / "x.csv").exists()


def test_bad_arguments_exit_2(capsys):
    for argv in (["simulate", "--rate", "-1"], ["bode", "--slip", "1.5"], ["frobnicate"]):
        with pytest.raises(SystemExit) as exit_info:
            main(argv)
        assert exit_info.value.code == 2
    capsys.readouterr()


def test_existing_bag_stops_the_run_before_anything_is_written(tmp_path, capsys):
    csv, bag = tmp_path / "keep.csv", tmp_path / "bag"
    csv.write_text("precious\n")
    bag.mkdir()
    assert main(["simulate", "-o", str(csv), "--bag", str(bag)]) == 2
    assert "exists already" in capsys.readouterr().err
    assert csv.read_text() == "precious\n"


def test_bode_finds_the_gear_walk_resonance(tmp_path, capsys):
    png = tmp_path / "bode.png"
    assert main(["bode", "--speeds", "20", "-o", str(png)]) == 0
    out = capsys.readouterr().out
    assert "with gear walk" in out and "resonance 7." in out
    assert "without gear walk" in out and "no resonance" in out
    assert png.stat().st_size > 10_000


def test_params_shows_and_writes_the_effective_set(tmp_path, capsys):
    assert main(["params", "--without", "gear_walk", "--set", "friction.theta1=0.9"]) == 0
    out = capsys.readouterr().out
    assert "reference_rig.yaml" in out and "0.9" in out
    written = tmp_path / "mine.yaml"
    assert main(["params", "--set", "friction.theta1=0.9", "--write", str(written)]) == 0
    assert main(["params", "--config", str(written)]) == 0
    assert "friction.theta1" in capsys.readouterr().out


def test_a_params_file_says_what_each_filled_slot_holds_in_its_equations_units(tmp_path):
    """A slot's code alone ('37.0') says nothing: the file names its basis function and its
    coefficient's unit, read from the schema (``params`` imports no equation's library, so
    it starts at once); each equation's library writes its law in that same unit."""
    from landing_gear_sim.diagnosis.equations.registry import LIBRARIES
    from landing_gear_sim.diagnosis.terms import slot_notes
    from landing_gear_sim.model import basis
    from landing_gear_sim.model import keys as K
    from landing_gear_sim.model.parameters import SPECS

    sign = basis.factor_code(basis.OMEGA, basis.SIGN)
    rig = load_parameters().replace({K.WHEEL_TERMS[1][0]: float(sign),
                                     K.WHEEL_TERMS[1][1]: 60.0}, "a bearing")
    assert slot_notes(rig) == {K.WHEEL_TERMS[1][0]: "sgn ω", K.WHEEL_TERMS[1][1]: "N m"}
    written = tmp_path / "mine.yaml"
    assert main(["params", "--config", str(_saved(rig, tmp_path)), "--write",
                 str(written)]) == 0
    assert "sgn ω" in written.read_text()
    units = {spec.key: spec.unit.removesuffix(" per phi") for spec in SPECS}
    for library in LIBRARIES:
        if library.slot is not None:
            assert units[library.slot.keys[0][1]] == library.unit, library.equation


def _saved(params, folder):
    path = folder / "rig.yaml"
    params.to_yaml(path)
    return path


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "landing-gear-sim"
    result = subprocess.run([str(script), "--version"], capture_output=True, text=True,
                            env=os.environ, check=False)
    assert result.returncode == 0 and "landing-gear-sim" in result.stdout


def test_an_unwritable_output_is_refused_before_the_work(tmp_path, capsys):
    """Once a traceback after 36 s of diagnosis, and the extended model lost."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    code = main(["diagnose", str(tmp_path), "--report", str(blocker / "report"),
                 "-o", str(tmp_path / "extended.yaml")])
    err = capsys.readouterr().err
    assert code == 2 and "cannot write there" in err and "calibrating" not in err
    assert len(err.strip().splitlines()) == 1
    assert main(["identify", str(tmp_path), "-o", str(tmp_path)]) == 2  # a folder, not a file
    assert "is a folder" in capsys.readouterr().err


@pytest.mark.parametrize("command", [["params", "--write", "out.yaml"],
                                     ["convert", "RUN", "out.csv"]])
def test_a_file_that_cannot_be_written_names_its_path_and_the_fix(tmp_path, capsys, command):
    """Issue 62, 20: `params --write` into a folder it cannot write printed a raw
    '[Errno 1] Operation not permitted'. A path through a file is refused the same way (as
    root, a read-only folder is not)."""
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    run = tmp_path / "run.csv"
    if "RUN" in command:
        assert main(["simulate", "--duration", "1", "--no-plot", "-o", str(run)]) == 0
        capsys.readouterr()
    argv = [str(run) if a == "RUN" else a for a in command[:-1]]
    assert main([*argv, str(blocker / command[-1])]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Errno" not in err, err
    assert str(blocker) in err and "cannot write there" in err and "choose" in err, err


def test_convert_writes_the_format_its_suffix_names_and_refuses_one_it_cannot(tmp_path,
                                                                              capsys):
    """Issue 62, 5: `convert bag OUT.CSV`, `out.tsv` and `out.parquet` all wrote a bag folder.
    The readers take suffixes case-insensitively, and so does the writer: what it writes
    reads back as the same run; a suffix it cannot write is refused before the work."""
    run = tmp_path / "run.csv"
    assert main(["simulate", "--duration", "1", "--no-plot", "-o", str(run)]) == 0
    original = read_csv(run)
    for name in ("OUT.CSV", "out.tsv", "out.txt"):
        assert main(["convert", str(run), str(tmp_path / name)]) == 0, name
        written = tmp_path / name
        assert written.is_file(), name
        again = read_run(written)
        assert np.allclose(again.pressure_pa, original.pressure_pa, rtol=1e-6), name
    capsys.readouterr()
    assert main(["convert", str(run), str(tmp_path / "out.parquet")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and ".parquet" in err and ".csv" in err, err
    assert not (tmp_path / "out.parquet").exists()
    assert main(["convert", str(run), str(tmp_path / "bag")]) == 0  # no suffix: a bag
    assert read_bag(tmp_path / "bag").pressure_pa.size == original.pressure_pa.size


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_without_never_swallows_the_campaign():
    """Issue 32: `diagnose --without gear_walk CAMPAIGN` once took the campaign as a second
    element and failed with 'the following arguments are required: RUN'."""
    args = build_parser().parse_args(["diagnose", "--without", "gear_walk", "out/c"])
    assert args.runs == [Path("out/c")] and args.start_without == ["gear_walk"]
    args = build_parser().parse_args(["diagnose", "out/c", "--without", "drag,gear_walk",
                                      "--without", "friction_curve"])
    assert args.start_without == ["drag", "gear_walk", "friction_curve"]


def test_an_unknown_element_to_leave_out_is_one_error_line_before_reading(tmp_path, capsys):
    assert main(["diagnose", "--without", "gear_wlak", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gear_wlak: not a model element" in err[0]


def test_every_option_and_argument_says_what_it_is():
    silent = [f"{name} {action.dest}"
              for name, sub in _subcommands(build_parser()).items()
              for action in sub._actions
              if not isinstance(action, argparse._HelpAction) and not action.help]
    assert not silent, silent


def test_help_loads_no_numerical_library():
    """`--help` and argument errors answer at once (issue 32: 1.5-24 s under load, most of
    it scipy): building the parser imports none of the numerical stack."""
    code = ("import sys; from landing_gear_sim.cli import build_parser; build_parser(); "
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'scipy', "
            "'numba', 'matplotlib', 'rosbags', 'rclpy', 'dask'}))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "[]"


@pytest.mark.parametrize("argv", [
    ["diagnose", "--without", "gear_walk", "/no/such/campaign"], ["identify", "/no/such"],
    ["validate", "/no/such"], ["metrics", "/no/such.csv"], ["compare", "/no/a.csv", "/no/b.csv"],
    ["convert", "/no/such.csv", "out.csv"], ["history", "/no/such"],
    ["simulate", "--config", "/no/such.yaml"], ["metrics", "/no/x.csv", "--mapping", "/no/m.yaml"],
])
def test_an_input_that_does_not_exist_is_refused_before_the_numerical_stack_loads(argv):
    """Issue 32: `diagnose /no/such` took 1.6 s on a quiet machine to say the folder is
    missing (the numerical stack loaded first); the parser says it."""
    code = ("import sys; from landing_gear_sim.cli import main\n"
            f"print(main({argv!r}))\n"
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'scipy', "
            "'numba', 'matplotlib', 'rosbags', 'rclpy', 'dask'}))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.split() == ["2", "[]"], (result.stdout, result.stderr)
    [line] = result.stderr.strip().splitlines()
    assert line.startswith("landing-gear-sim: error: /no/") and \
        line.endswith(": no such file or folder"), line


def test_the_compile_note_is_printed_only_while_compiling(tmp_path, capsys):
    """Issue 32: "the first run compiles the physics, ~10 s" was printed on every run."""
    argv = ["simulate", "--profile", "steps", "--duration", "0.5", "--no-plot"]
    assert main([*argv, "-o", str(tmp_path / "a.csv")]) == 0  # compiles, or loads the cache
    capsys.readouterr()
    assert main([*argv, "-o", str(tmp_path / "b.csv")]) == 0
    err = capsys.readouterr().err
    assert "simulated in" in err and "compil" not in err


def test_a_shuffled_campaign_names_its_runs_in_the_order_they_were_made(tmp_path):
    """Issue 64: wear is judged by run order; a campaign made out of pressure order is
    what tells a brake that wears from a gain that depends on pressure."""
    assert main(["campaign", str(tmp_path / "c"), "--shuffled", "--seed", "158"]) == 0
    names = sorted(p.stem for p in (tmp_path / "c").glob("*.csv"))
    assert [n[:6] for n in names] == [f"run{k:02d}_" for k in range(1, 9)]
    made = [n[6:] for n in names]
    assert sorted(made) == sorted(STANDARD_RUNS[:8]) and made != sorted(made)
