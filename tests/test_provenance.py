"""Labels true to their sources: every controller preset says which of its numbers come
from the source (and where) and which are posturelab's own, and the cited numbers equal
the source's as printed.

Source fixture: PMC5664365 Table 1 ("Default value" column), as the page
https://pmc.ncbi.nlm.nih.gov/articles/PMC5664365/table/T1 prints it: J 66 kg m², m 75 kg,
h 0.83 m, g 9.81 m/s², K 40.5 Nm/rad, B 68.8 Nms/rad, ω0 16.8 rad/s, β 0.99, τD 0.097 s,
WP 0.8, WV 0.8, KP 943.9 Nm/rad, KD 313.5 Nms/rad, KF 0.0018 rad/Nm, τF 17.4 s.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from posturelab.model.controllers import CONTROLLERS, PRESET_NUMBERS, get_controller

#: PMC5664365 Table 1, the values the page prints (module notes).
PMC5664365_TABLE_1 = {"J": 66.0, "m": 75.0, "h": 0.83, "g": 9.81, "K": 40.5, "B": 68.8,
                      "ω0": 16.8, "β": 0.99, "τ_D": 0.097, "W_P": 0.8, "W_V": 0.8,
                      "K_P": 943.9, "K_D": 313.5, "K_F": 0.0018, "τ_F": 17.4}


@pytest.mark.parametrize("name", list(CONTROLLERS))
def test_every_number_of_every_preset_has_a_provenance(name):
    preset = get_controller(name)
    fields = dict(preset.provenance)
    assert set(fields) == {f for f, _ in PRESET_NUMBERS}
    text = preset.provenance_text()
    for field, symbol in PRESET_NUMBERS:
        assert f"{symbol} = {getattr(preset, field):.4g}:" in text


def test_the_cited_numbers_of_icm_pmc5664365_are_table_1s():
    preset = get_controller("icm-pmc5664365")
    table = PMC5664365_TABLE_1
    mgh = table["m"] * table["g"] * table["h"]
    for field, symbol, per_mgh in (("intrinsic_stiffness", "K", True),
                                   ("intrinsic_viscosity", "B", True),
                                   ("active_stiffness", "K_P", True),
                                   ("active_viscosity", "K_D", True),
                                   ("feedback_delay", "τ_D", False),
                                   ("proprioceptive_weight", "W_P", False)):
        prov = preset.provenance_of(field)
        assert prov.from_source and prov.where == f"PMC5664365 Table 1, {symbol}"
        assert prov.source_value == table[symbol]
        expected = table[symbol] / mgh if per_mgh else table[symbol]
        assert getattr(preset, field) == pytest.approx(expected, rel=1e-12)
    assert preset.assumed() == ()


def test_the_peterka_2002_preset_says_what_is_posturelabs():
    preset = get_controller("peterka-2002")
    assert preset.proprioceptive_weight == 1.0
    assert not preset.provenance_of("proprioceptive_weight").from_source  # W = 1 is ours
    assert "W = 1: posturelab's assumption" in preset.provenance_text()
    assert {"K/mgh", "B/mgh", "W"} <= set(preset.assumed())
    assert "posturelab's choices" in preset.citation


def test_help_prints_the_provenance():
    p = subprocess.run([sys.executable, "-m", "posturelab", "simulate", "--help"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0
    flat = " ".join(p.stdout.split())
    assert "W = 1: posturelab's assumption" in flat
    assert "K_P/mgh = 1.546: PMC5664365 Table 1, K_P = 943.9 N·m/rad" in flat
