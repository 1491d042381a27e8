"""ehm.analysis.frf: what the transfer-function functions refuse (issue 38, item 5: nothing silent)."""

from __future__ import annotations

import pytest

import ehm
from ehm.errors import InputError


@pytest.mark.parametrize("freq, bad", [([-1.0, 0.0, 1.0], "-1 Hz"), ([0.0, 1.0], "0 Hz"), (0.0, "0 Hz")])
def test_linear_frf_refuses_frequencies_at_or_below_zero(human, freq, bad):
    # issue 38: linear_frf(freq_hz=[-1, 0, 1]) returned gains at -1 and 0 Hz
    with pytest.raises(InputError, match=f"freq_hz holds {bad}: a frequency response needs frequencies above 0 Hz"):
        ehm.linear_frf(human, "z", freq_hz=freq)


def test_linear_frf_takes_one_positive_frequency(human):
    table = ehm.linear_frf(human, "z", freq_hz=5.0)
    assert table.curve("z", "head", "z").freq_hz.tolist() == [5.0]


@pytest.mark.parametrize("band", [(0.0, 12.0), (-1.0, 12.0), (12.0, 1.0), (1.0,)])
def test_time_domain_frf_refuses_a_band_at_or_below_zero(human, band):
    with pytest.raises(InputError, match="band_hz"):
        ehm.time_domain_frf(human, "z", duration_s=10.0, band_hz=band)
