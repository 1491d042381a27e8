"""Whole-body vibration evaluation after ISO 2631-1:1997, and the spinal dose of ISO 2631-5:2018.

Frequency weightings, their causal digital filters and the evaluation values of the standard:
weighted rms, maximum transient vibration value, vibration dose value, crest factor, motion sickness
dose value, vibration total value and the comfort reactions of its Annex C.

Pure array functions: no engine, no plotting, no files, nothing computed at import time.

Public API
----------
WEIGHTINGS                              names of the weightings: Wk, Wd, Wf, Wc, We, Wj
frequency_weighting(name, freq_hz)      exact analog response (complex)
weighting_sos(name, fs_hz)              second-order sections of the causal digital filter, any rate from 5 f1
weighting_deviation_db(name, fs_hz)     its largest deviation from the analog magnitude up to 0.4 fs
weight(name, signal, fs_hz)             causal weighting of a whole record
WeightingFilter(name, fs_hz)            the same filter sample by sample or block by block
band_share_outside(name, low, high)     share of a weighting's power outside the band an input covers
ComfortMetrics, metrics(signal, fs_hz, weighting)
total_value(ax, ay, az, fs_hz, purpose="comfort", seated=True)
comfort_reaction(a_w)                   ISO 2631-1 Annex C label(s)
seat_value(a_w_body, a_w_seat)          SEAT-style ratio in %
ComfortAccumulator(weighting, fs_hz)    the metrics of a record fed block by block, in constant memory
SpineExposure, SpinalDose               ISO 2631-5: the daily exposure and the person; the figures of a record
spinal_dose(seat_az, fs_hz, exposure)   ISO 2631-5 by the standard's route, from the seat's vertical acceleration
spinal_dose_from_lumbar(az, fs_hz, ...) the same from an acceleration already the lumbar spine's (a body model's)

Modules: ``weighting`` (the weightings and their digital filters, with their definition), ``values``
(evaluation values of a whole record), ``streaming`` (``ComfortAccumulator``), ``spine`` (ISO 2631-5:
lumbar response, peaks, doses, R), ``checks`` (input checks).
"""

from .spine import SpinalDose, SpineExposure, spinal_dose, spinal_dose_from_lumbar
from .streaming import ComfortAccumulator
from .values import ComfortMetrics, comfort_reaction, metrics, seat_value, total_value
from .weighting import (
                        ACCURATE_UP_TO_FS,
                        BAND_WARNING_SHARE,
                        WEIGHTING_BANDS_HZ,
                        WEIGHTINGS,
                        WeightingFilter,
                        band_share_outside,
                        frequency_weighting,
                        weight,
                        weighting_deviation_db,
                        weighting_sos,
)

__all__ = [
    "WEIGHTINGS", "ACCURATE_UP_TO_FS", "frequency_weighting", "weighting_sos", "weighting_deviation_db", "weight",
    "WeightingFilter", "ComfortMetrics", "ComfortAccumulator", "metrics", "total_value", "comfort_reaction",
    "seat_value", "WEIGHTING_BANDS_HZ", "BAND_WARNING_SHARE", "band_share_outside",
    "SpineExposure", "SpinalDose", "spinal_dose", "spinal_dose_from_lumbar",
]
