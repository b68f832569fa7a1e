"""Figures (posturelab.viz.plots) and the stick-figure GIF (posturelab.viz.animation).

The figures are checked as a reader would need them: every axis carries a
label with a unit in brackets, a legend and a title; the functions draw on
the Axes they are given and return it; nothing goes through pyplot.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from posturelab.errors import ParameterError, PostureLabError, UnknownNameError
from posturelab.scenarios import builtin_scenario
from posturelab.simulation import FOOT_FROM_LITERATURE
from posturelab.viz.plots import (
    new_figure,
    plot_angle_angle,
    plot_cog_phase,
    plot_pair_torques,
    plot_run_overview,
    plot_time_histories,
    save_figure,
)


@pytest.fixture(scope="module")
def backward():
    """Figs. 3–7 scenario, shortened to 1.5 s at 200 Hz output (fast, same physics)."""
    sc = builtin_scenario("paper-backward-case1")
    return sc, sc.run(duration=1.5, sample_rate=200.0)


@pytest.fixture(scope="module")
def falling():
    """Fig. 9 scenario (case 2, forward): falls at about 1.19 s."""
    sc = builtin_scenario("paper-forward-case2")
    return sc, sc.run(duration=2.0, sample_rate=200.0)


def _assert_labelled(ax: Axes) -> None:
    """x and y labels name a unit in brackets; the axes has a title and a legend."""
    assert "[" in ax.get_xlabel() and "]" in ax.get_xlabel(), ax.get_xlabel()
    assert "[" in ax.get_ylabel() and "]" in ax.get_ylabel(), ax.get_ylabel()
    assert ax.get_title()
    assert ax.get_legend() is not None


def test_no_pyplot_import():
    """The plotting modules never load pyplot (no global state, safe on servers)."""
    code = ("import sys, posturelab.viz.plots, posturelab.viz.animation, "
            "posturelab.paper.report; "
            "print('matplotlib.pyplot' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_time_histories_new_figure(backward):
    _, r = backward
    axes = plot_time_histories(r, link_names=("leg", "thigh", "torso"))
    assert len(axes) == 2
    for ax in axes:
        _assert_labelled(ax)
    assert "[rad]" in axes[0].get_ylabel() and "[rad/s]" in axes[1].get_ylabel()
    assert "[s]" in axes[1].get_xlabel()
    assert len(axes[0].get_lines()) >= 3 and "leg" in axes[0].get_legend().texts[0].get_text()


def test_time_histories_accepts_axes(backward):
    _, r = backward
    fig, axes = new_figure(1, 2)
    out = plot_time_histories(r, axes)
    assert out is axes
    fig2, ax = new_figure()
    assert plot_time_histories(r, ax) is ax
    _assert_labelled(ax)
    with pytest.raises(ParameterError):
        plot_time_histories(r, [ax])


def test_time_histories_marks_fall(falling):
    _, r = falling
    axes = plot_time_histories(r)
    texts = [t.get_text() for t in axes[0].get_legend().texts]
    assert any(t.startswith("fall at t = 1.1") for t in texts), texts


def test_angle_angle(backward):
    _, r = backward
    fig, ax = new_figure()
    assert plot_angle_angle(r, ax) is ax
    _assert_labelled(ax)
    assert "theta_1" in ax.get_xlabel()
    # θ2 and θ3 against θ1, plus the diagonal
    xs = [line.get_xdata() for line in ax.get_lines() if len(line.get_xdata()) == r.time.size]
    assert len(xs) == 2 and np.allclose(xs[0], r.theta[:, 0])


def test_pair_torques_fig5_and_fig6(backward):
    _, r = backward
    fig, ax = new_figure()
    assert plot_pair_torques(r, ax=ax) is ax
    _assert_labelled(ax)
    assert "[N·m]" in ax.get_ylabel()
    labels = [t.get_text() for t in ax.get_legend().texts]
    assert labels == ["ankle pair", "knee pair", "hip pair", "gastrocnemius pair"]
    ax6 = plot_pair_torques(r, ("quadriceps",))
    assert [t.get_text() for t in ax6.get_legend().texts] == ["quadriceps pair"]
    j = r.pair_names.index("quadriceps")
    assert np.allclose(ax6.get_lines()[0].get_ydata(), r.pair_torques[:, j])


def test_pair_torques_unknown_name(backward):
    _, r = backward
    with pytest.raises(UnknownNameError, match="quadriceps"):
        plot_pair_torques(r, ("soleus",))


def test_cog_phase(backward):
    _, r = backward
    fig, ax = new_figure()
    out = plot_cog_phase(r, ax, base_of_support=FOOT_FROM_LITERATURE)
    assert out is ax
    _assert_labelled(ax)
    assert "[m]" in ax.get_xlabel() and "[m/s]" in ax.get_ylabel()
    labels = [t.get_text() for t in ax.get_legend().texts]
    assert any(lab.startswith("start") for lab in labels)
    assert any(lab.startswith("end") for lab in labels)
    assert any("heel" in lab for lab in labels)  # the shaded foot
    with pytest.raises(ParameterError):
        plot_cog_phase(r, base_of_support=(0.1, 0.2))


def test_cog_phase_overlay_and_fall(backward, falling):
    _, r = backward
    _, f = falling
    ax = plot_cog_phase(r, label="backward")
    plot_cog_phase(f, ax, label="falls", color="r")
    labels = [t.get_text() for t in ax.get_legend().texts]
    assert len(labels) == len(set(labels))  # one legend entry per label
    assert any(lab.startswith("fall (t = 1.1") for lab in labels)


def test_run_overview(backward, tmp_path):
    _, r = backward
    fig = plot_run_overview(r, base_of_support=FOOT_FROM_LITERATURE)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == 4
    for ax in fig.axes:
        assert "[" in ax.get_xlabel() and "[" in ax.get_ylabel()
    assert fig.get_suptitle()
    out = save_figure(fig, tmp_path / "run.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert list(tmp_path.iterdir()) == [out]  # no temporary file left
    with pytest.raises(ParameterError, match=".png"):
        save_figure(fig, tmp_path / "run.bmp")


def test_animate_writes_gif(tmp_path):
    from PIL import Image

    from posturelab.viz.animation import animate

    sc = builtin_scenario("paper-forward-case2")
    r = sc.run(duration=1.5, sample_rate=100.0)  # falls at ~1.19 s
    path = animate(r, sc.body, tmp_path / "run.gif", fps=10)
    assert path == tmp_path / "run.gif"
    with Image.open(path) as im:
        assert im.format == "GIF"
        assert im.n_frames > 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.gif"]


def test_animate_bad_input(tmp_path, backward):
    from posturelab.model.body import Body
    from posturelab.viz.animation import animate

    sc, r = backward
    with pytest.raises(ParameterError, match=".gif"):
        animate(r, sc.body, tmp_path / "run.mp4")
    with pytest.raises(ParameterError, match="fps"):
        animate(r, sc.body, tmp_path / "run.gif", fps=0)
    with pytest.raises(PostureLabError, match="does not exist"):
        animate(r, sc.body, tmp_path / "missing" / "run.gif")
    two = Body.from_arrays([30.0, 30.0], [0.9, 0.8], [0.5, 0.4], [1.0, 1.0])
    with pytest.raises(ParameterError, match="links"):
        animate(r, two, tmp_path / "run.gif")
    assert list(tmp_path.iterdir()) == []


def test_joint_positions_reach(body):
    """Upright, the top joint is at the summed link lengths; tilted, at l·sin θ."""
    from posturelab.viz.animation import joint_positions

    up = joint_positions(body, np.zeros(3))
    assert np.allclose(up[-1], [0.0, body.lengths.sum()])
    tilt = joint_positions(body, np.full((2, 3), 0.3))
    assert tilt.shape == (2, 4, 2)
    assert np.allclose(tilt[0, -1], body.lengths.sum() * np.array([np.sin(0.3), np.cos(0.3)]))


# -- several runs on one figure ------------------------------------------------------------


def _legend_texts(ax: Axes) -> list[str]:
    return [t.get_text() for t in ax.get_legend().texts]


def test_time_histories_several_runs(backward, falling):
    """Links keep their colours, each run its own line style; each label appears once."""
    _, r = backward
    _, f = falling
    axes = plot_time_histories([r, f], labels=["backward", "forward, case 2"])
    for ax in axes:
        texts = _legend_texts(ax)
        assert len(texts) == len(set(texts)), texts
        assert "backward" in texts and "forward, case 2" in texts
        assert sum(t.startswith("forward, case 2: fall at t = 1.1") for t in texts) == 1
    data = [line for line in axes[0].get_lines() if len(line.get_xdata()) == f.time.size]
    assert len(data) >= 3 and np.allclose(data[0].get_ydata(), f.theta[:, 0])
    styles = {line.get_linestyle() for line in axes[0].get_lines() if np.size(line.get_xdata()) > 2}
    assert {"-", "--"} <= styles
    with pytest.raises(ParameterError, match="one label per run"):
        plot_time_histories([r, f], labels=["only one"])
    with pytest.raises(ParameterError, match="two Axes"):
        plot_time_histories([r, f], new_figure()[1])
    with pytest.raises(ParameterError, match="SimulationResult"):
        plot_time_histories("run.csv")
    with pytest.raises(ParameterError, match="at least one"):
        plot_time_histories([])


def test_angle_angle_and_torques_several_runs(backward, falling):
    _, r = backward
    _, f = falling
    ax = plot_angle_angle([r, f], labels=["a", "b"])
    texts = _legend_texts(ax)
    assert len(texts) == len(set(texts)) and {"a", "b", "end", "fall"} <= set(texts)
    ax = plot_pair_torques([r, f], labels=["a", "b"])
    texts = _legend_texts(ax)
    assert texts.count("ankle pair") == 1 and {"a", "b"} <= set(texts)
    ankle = [line for line in ax.get_lines() if line.get_label() == "ankle pair"]
    assert len(ankle) == 1 and np.allclose(ankle[0].get_ydata(),
                                           r.pair_torques[:, r.pair_names.index("ankle")])


def test_cog_phase_several_runs_shade_foot_once(backward, falling):
    """A list of runs, or repeated calls on one Axes: the foot shaded once, labels once."""
    _, r = backward
    _, f = falling
    ax = plot_cog_phase([r, f], label=["backward", "forward"],
                        base_of_support=FOOT_FROM_LITERATURE)
    plot_cog_phase(r, ax, label="backward again", base_of_support=FOOT_FROM_LITERATURE)
    assert len(ax.patches) == 1
    texts = _legend_texts(ax)
    assert len(texts) == len(set(texts))
    assert {"backward", "forward", "backward again", "fall", "end"} <= set(texts)
    colours = {line.get_color() for line in ax.get_lines() if np.size(line.get_xdata()) > 2}
    assert len(colours) == 3  # the repeated call carries on the colour cycle
    with pytest.raises(ParameterError, match="one colour per run"):
        plot_cog_phase([r, f], color="k")


def test_bode_draws_a_table_with_and_without_standard_errors():
    """A table of FRFs (fit-frf's JSON input) is drawn like an estimate: its 95 % band from
    the standard errors (1.96 se each side), none without them."""
    from posturelab.frequency.table import FRFTable
    from posturelab.viz.plots import plot_bode

    f = np.array([0.1, 0.5, 1.0])
    h = np.array([1.0 + 0.1j, 0.8 - 0.3j, 0.3 - 0.5j])
    gain_se = np.array([0.05, 0.04, 0.03])
    with_se = FRFTable(f, h, gain_se=gain_se, phase_se_deg=np.array([2.0, 3.0, 4.0]))
    bare = FRFTable(f, h)
    fig = plot_bode([with_se, bare], ["with se", "bare"])
    gain_axes = fig.axes[0]
    bands = gain_axes.collections
    assert len(bands) == 1  # the table without standard errors has no band
    top = bands[0].get_paths()[0].vertices[:, 1].max()
    assert top == pytest.approx(float(np.max(np.abs(h) + 1.96 * gain_se)))
    assert [line.get_label() for line in gain_axes.get_lines()] == ["with se", "bare"]
