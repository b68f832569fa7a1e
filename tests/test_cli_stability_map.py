"""The ``stability-map`` subcommand: outputs, one-line errors (exit 2), nothing half-written.

The map's numbers are checked against linear.analyse in test_batch_linear.py; here
the CSV is checked against the same single-case path at a few points.
"""

import csv
import re

import numpy as np
import pytest

from posturelab.cli import main
from posturelab.cli import stability_map as cli_map
from posturelab.linear import analyse
from posturelab.model.muscles import paper_muscles
from posturelab.viz import maps as viz_maps

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(capsys, *argv):
    """Run the CLI in-process; return (exit code, stdout, stderr)."""
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


@pytest.fixture(autouse=True)
def compiled_evaluator(tmp_path_factory, capsys):
    """The map's numba kernels compiled (or loaded from the cache) before every test here, so
    that the one-time compile notice cannot reach a test's stderr (under pytest-xdist any of
    them may run before another has compiled them)."""
    folder = tmp_path_factory.mktemp("warm")
    assert main(["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
                 "stiffness:gastrocnemius:0:1000",
                 "--resolution", "2", "--out", str(folder / "map.png")]) == 0
    capsys.readouterr()


def test_small_map_writes_png_and_csv(tmp_path, capsys, body, compiled_evaluator):
    out = tmp_path / "map.png"
    code, stdout, stderr = run(capsys, "stability-map", "--x", "stiffness:ankle:0:2000",
                               "--y", "stiffness:gastrocnemius:0:1000", "--resolution", "6",
                               "--out", str(out))
    assert code == 0, stderr
    assert stderr == ""  # no progress bar: stderr is not a terminal
    assert "map.png" in stdout and "map.csv" in stdout
    assert out.read_bytes()[:8] == PNG_MAGIC
    header, rows = read_csv(tmp_path / "map.csv")
    assert header == ["stiffness:ankle", "stiffness:gastrocnemius", "max_real_part", "stable"]
    assert len(rows) == 36
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.csv", "map.png"]
    plain = tmp_path / "plain"
    plain.write_text("")  # outputs get the mode of a normally created file, not 0600
    assert out.stat().st_mode & 0o777 == plain.stat().st_mode & 0o777
    plain.unlink()
    for ankle, gastro, max_real, stable in rows[::7]:
        single = analyse(body, paper_muscles(
            stiffness=[float(ankle), 300, 300, 300, float(gastro)]))
        assert stable == ("1" if single.stable else "0")
        assert float(max_real) == pytest.approx(single.max_real_part, abs=1e-8)


def test_viscosity_axis_case_and_svg(tmp_path, capsys):
    out = tmp_path / "ratio.svg"
    code, _, stderr = run(capsys, "stability-map", "--x", "viscosity_ratio:0.05:0.5",
                          "--y", "stiffness:hip:0:1000", "--resolution", "3", "--case", "6a",
                          "--out", str(out), "--progress")
    assert code == 0, stderr
    # --progress draws the bar even off a terminal, to the last of the 3 × 3 sets
    assert re.search(r"\] 100% 9/9 sets", stderr), stderr
    assert out.read_text(encoding="utf-8").lstrip().startswith("<?xml")
    header, rows = read_csv(tmp_path / "ratio.csv")
    assert header == ["viscosity_ratio", "stiffness:hip", "max_real_part", "stable"]
    assert np.allclose(sorted({float(r[0]) for r in rows}), [0.05, 0.275, 0.5])


def test_fixed_viscosity_ratio(tmp_path, capsys):
    code, _, stderr = run(capsys, "stability-map", "--x", "stiffness:ankle:0:2000", "--y",
                          "stiffness:knee:0:500",
                          "--resolution", "2", "--viscosity-ratio", "0",
                          "--out", str(tmp_path / "m.png"))
    assert code == 0, stderr
    _, rows = read_csv(tmp_path / "m.csv")
    assert {r[3] for r in rows} == {"0"}  # no damping: never asymptotically stable


@pytest.mark.parametrize("argv,message", [
    (["--x", "ankel:0:1", "--y", "stiffness:hip:0:1"],
     "unknown parameter 'ankel'; known parameters: stiffness:ankle, stiffness:knee, "
     "stiffness:hip, stiffness:quadriceps, stiffness:gastrocnemius, viscosity_ratio"),
    (["--x", "ankle:0:1", "--y", "stiffness:hip:0:1"],
     "--x parameter 'ankle' is now called 'stiffness:ankle'"),
    (["--x", "stiffness:ankle:2000:0", "--y", "stiffness:hip:0:1"], "LO < HI"),
    (["--x", "stiffness:ankle:0:abc", "--y", "stiffness:hip:0:1"], "HI must be a number"),
    (["--x", "stiffness:ankle:0", "--y", "stiffness:hip:0:1"], "NAME:LO:HI"),
    (["--x", "stiffness:ankle:-5:10", "--y", "stiffness:hip:0:1"], "LO must be >= 0"),
    (["--x", "stiffness:ankle:0:nan", "--y", "stiffness:hip:0:1"], "finite"),
    (["--x", "stiffness:hip:0:1", "--y", "stiffness:hip:0:1"], "different parameters"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--resolution", "1"], "[2, 1414]"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--resolution", "5001"],
     "[2, 1414]"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--resolution", "ten"], "integer"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--case", "8"], "known cases"),
    (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--viscosity-ratio", "-1"], ">= 0"),
    (["--x", "viscosity_ratio:0:1", "--y", "stiffness:hip:0:1", "--viscosity-ratio", "0.3"],
     "axis"),
])
def test_bad_input_one_line_exit_2(tmp_path, capsys, argv, message):
    code, stdout, stderr = run(capsys, "stability-map", *argv,
                               "--out", str(tmp_path / "map.png"))
    assert code == 2
    assert stdout == ""
    assert stderr.count("\n") == 1 and stderr.startswith("posturelab: error: ")
    assert message in stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("out,message", [
    ("missing_dir/map.png", "does not exist"),
    ("a_file.txt/map.png", "does not exist"),
    ("map.csv", "figure suffix"),
    ("map", "figure suffix"),
    ("map.xyz", "figure suffix"),
])
def test_bad_out_one_line_exit_2(tmp_path, capsys, out, message):
    (tmp_path / "a_file.txt").write_text("not a directory")
    code, _, stderr = run(capsys, "stability-map", "--x", "stiffness:ankle:0:1", "--y",
                          "stiffness:hip:0:1",
                          "--resolution", "2", "--out", str(tmp_path / out))
    assert code == 2
    assert stderr.count("\n") == 1 and message in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file.txt"]


def test_write_failure_leaves_nothing_and_keeps_old_files(tmp_path, capsys, monkeypatch):
    """A failure while writing: one-line error, old outputs untouched, no temporaries."""
    (tmp_path / "map.png").write_bytes(b"old figure")
    (tmp_path / "map.csv").write_text("stiffness:ankle,stiffness:hip,max_real_part,stable\n")

    def disk_full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(viz_maps, "plot_stability_map", disk_full)
    code, _, stderr = run(capsys, "stability-map", "--x", "stiffness:ankle:0:1", "--y",
                          "stiffness:hip:0:1",
                          "--resolution", "2", "--out", str(tmp_path / "map.png"))
    assert code == 2
    assert stderr.count("\n") == 1 and "No space left on device" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["map.csv", "map.png"]
    assert (tmp_path / "map.png").read_bytes() == b"old figure"
    assert (tmp_path / "map.csv").read_text() == ("stiffness:ankle,stiffness:hip,"
                                                  "max_real_part,stable\n")


def test_interrupt_leaves_nothing(tmp_path, capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(viz_maps, "plot_stability_map", interrupted)
    code, _, _ = run(capsys, "stability-map", "--x", "stiffness:ankle:0:1", "--y",
                     "stiffness:hip:0:1",
                     "--resolution", "2", "--out", str(tmp_path / "map.png"))
    assert code == 130
    assert list(tmp_path.iterdir()) == []


def test_progress_bar_draws_in_place():
    """The one bar every command draws (posturelab._progress): redrawn in place with carriage
    returns, a repeated count not redrawn, the line ended when closed."""
    import io

    from posturelab._progress import Progress

    stream = io.StringIO()
    bar = Progress(label="map", unit="sets", stream=stream, width=10, every_step=True)
    for done in (0, 5, 5, 10):
        bar(done, 10)
    assert "\n" not in stream.getvalue()
    bar.close()
    text = stream.getvalue()
    assert text.count("\r") == 4  # 0, 5, 10 and the closing line; the repeated 5 is not drawn
    assert "map [#####.....]  50% 5/10 sets" in text
    assert re.search(r"map \[#{10}\] 100% 10/10 sets \[[^]]*\]\n$", text), text


def test_real_subprocess_bad_axis_is_one_line(tmp_path):
    """The installed entry point: a bad axis gives one line on stderr and exit 2."""
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-m", "posturelab", "stability-map", "--x", "stiffness:ankle:5:1",
         "--y", "stiffness:hip:0:1", "--out", str(tmp_path / "m.png")],
        capture_output=True, encoding="utf-8", timeout=120, check=False,
    )
    assert proc.returncode == 2
    assert proc.stdout == ""
    assert proc.stderr.strip().count("\n") == 0 and "LO < HI" in proc.stderr
    assert list(tmp_path.iterdir()) == []


def test_known_figure_formats_are_matplotlib_formats():
    """--out suffixes accepted without importing matplotlib are ones it writes."""
    from matplotlib.figure import Figure

    supported = set(Figure().canvas.get_supported_filetypes())
    assert cli_map.FIGURE_FORMATS <= supported
    assert {"png", "pdf", "svg"} <= cli_map.FIGURE_FORMATS and "csv" not in supported


def _eig_max_real(body, n_links, stiffness, ratio):
    """The largest real part of the poles, from numpy eigvals of the state matrix built here
    from the body's mass matrix and gravity torques (independent of the batch kernels)."""
    from posturelab.model.dynamics import mass_matrix

    n = n_links
    E = np.eye(n) - np.eye(n, k=-1)  # one pair per joint: stretch θ_j − θ_{j−1}
    K = E.T @ np.diag(stiffness) @ E
    J0 = mass_matrix(body, np.zeros(n))
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = np.linalg.solve(J0, body.gravity * np.diag(body.gravity_coefficients) - K)
    A[n:, n:] = -np.linalg.solve(J0, ratio * K)
    return float(np.linalg.eigvals(A).real.max())


@pytest.mark.parametrize("argv,n_links,base,ratio", [
    (["--body", "paper-1link", "--stiffness", "700", "--y", "viscosity_ratio:0.01:0.6"],
     1, [700.0], None),
    (["--body", "paper-2link", "--stiffness", "900,250", "--y", "stiffness:hip:0:800"],
     2, [900.0, 250.0], 0.25),
    (["--height", "1.8", "--mass", "82", "--case", "1", "--y", "stiffness:hip:0:800"],
     3, [500.0, 300.0, 300.0], 0.25),
])
def test_pair_maps_for_any_body_are_numpy_s_eigenvalues(tmp_path, argv, n_links, base, ratio):
    """`stability-map` over pair stiffness on a one-, two- and anthropometric three-link body
    (a real subprocess): every CSV row equals numpy's eigenvalues of the state matrix."""
    import subprocess
    import sys

    import posturelab as pl

    out = tmp_path / "any.png"
    proc = subprocess.run([sys.executable, "-m", "posturelab", "stability-map",
                           "--x", "stiffness:ankle:0:2500", *argv, "--resolution", "5", "--out",
                           str(out)], capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert "parameter sets of body" in proc.stdout
    header, rows = read_csv(tmp_path / "any.csv")
    assert header[0] == "stiffness:ankle" and len(rows) == 25
    body = (pl.body_from_anthropometry(1.8, 82.0) if "--height" in argv
            else pl.get_body(argv[1]))
    for row in rows:
        x, y, max_real, stable = float(row[0]), float(row[1]), float(row[2]), row[3]
        if n_links == 3:
            # case 1 with the hip axis: the gastrocnemius and quadriceps at 300 (five pairs)
            muscles = paper_muscles(stiffness=[x, 300, y, 300, 300])
            want = analyse(body, muscles).max_real_part
        else:
            gains = [x] if n_links == 1 else [x, y]
            want = _eig_max_real(body, n_links, gains, y if ratio is None else ratio)
        assert max_real == pytest.approx(want, abs=1e-7 * max(1.0, abs(want)))
        assert stable == ("1" if want < -1e-9 else "0")


def test_pair_map_of_another_body_refuses_what_it_cannot_map(tmp_path, capsys):
    for argv, words in (
            (["--body", "paper-1link", "--x", "stiffness:ankle:0:1", "--y", "viscosity_ratio:0:1"],
             "give --stiffness (1 value: ankle)"),
            (["--body", "paper-1link", "--stiffness", "600", "--x", "stiffness:ankle:0:1",
              "--y", "stiffness:hip:0:1"],
             "unknown parameter 'stiffness:hip'; known parameters: stiffness:ankle, "
             "viscosity_ratio"),
            (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--gastrocnemius",
              "one-sided"], "switching point"),
            (["--x", "stiffness:ankle:0:1", "--y", "stiffness:hip:0:1", "--controller",
              "peterka-2002"], "--controller is for the delayed map")):
        code, _, err = run(capsys, "stability-map", *argv, "--out", str(tmp_path / "e.png"))
        assert code == 2 and words in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_map_image_is_matplotlib_s_own_float32_of_the_rgba_bytes():
    """The figure hands imshow float32 RGBA = bytes / 255 (what matplotlib makes of uint8
    RGBA when drawing): the PNG is byte for byte the one the uint8 image gives."""
    import io

    from posturelab.linear.batch import stability_map

    smap = stability_map(("stiffness:ankle", 0, 2000), ("stiffness:gastrocnemius", 0, 1000), 37)
    pngs = []
    for as_uint8 in (False, True):
        fig = viz_maps.plot_stability_map(smap)  # a fresh figure each (layout as drawn once)
        image = fig.axes[0].get_images()[0]
        rgba = image.get_array()
        assert rgba.dtype == np.float32
        if as_uint8:
            as_bytes = np.rint(np.asarray(rgba) * 255).astype(np.uint8)
            assert np.array_equal(np.divide(as_bytes, 0xff, dtype=np.float32), rgba)
            image.set_data(as_bytes)
        stream = io.BytesIO()
        fig.savefig(stream, format="png", dpi=60)
        pngs.append(stream.getvalue())
    assert pngs[0] == pngs[1]


def test_main_with_arguments_does_not_freeze_the_collector(tmp_path, capsys):
    """Only the program itself (main() without arguments, which exits next) freezes the
    garbage collector; a caller passing argv keeps a normal process."""
    import gc

    before = gc.get_freeze_count()
    code = main(["stability-map", "--x", "stiffness:ankle:0:2000", "--y",
                 "stiffness:gastrocnemius:0:1000", "--resolution", "5", "--out",
                 str(tmp_path / "m.png")])
    assert code == 0
    assert gc.get_freeze_count() == before
