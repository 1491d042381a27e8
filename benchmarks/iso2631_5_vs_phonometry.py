"""ISO 2631-5 spinal dose: ehm (ehm.standards.comfort.spine) against an independent implementation, phonometry.

phonometry (MIT, https://github.com/jmrplens/phonometry) computes the lumbar response in the frequency domain
(Formula 2), ehm with a causal filter at the record's rate.  Both run on the same SYNTHETIC signals: a shock train
(500 Hz), random vibration with shocks (256 Hz and 1 kHz), and phonometry's own end-to-end test input; and on the
standard's Annex C example (five peaks of 40 m/s^2).  ehm does not depend on phonometry: it runs here in a Python
of its own (phonometry needs Python 3.13 or newer), e.g.

    python3.13 -m venv /tmp/phon-venv && /tmp/phon-venv/bin/pip install phonometry
    python benchmarks/iso2631_5_vs_phonometry.py --phonometry-python /tmp/phon-venv/bin/python
"""

from __future__ import annotations

import argparse
import json
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from scipy import signal

from ehm.standards.comfort import spine

_PHONOMETRY = """
import json, sys, numpy as np
try:
    from phonometry.vibration import multiple_shock_vibration as v
except ImportError:
    from phonometry.vibration.human import multiple_shock as v
d = np.load(sys.argv[1]); out = {}
for k in [k for k in d.files if not k.endswith("__fs")]:
    x, fs = d[k], float(d[k + "__fs"])
    r = v.multiple_shock_assessment(x, fs, start_age=20, years=20, days_per_year=120, exposure_time=8 * 3600.0,
                                    measurement_time=x.size / fs, sex="male")
    out[k] = {"peaks": len(r.peaks), "peak_max": float(r.peaks.max()), "sd": r.compression_dose, "r": r.risk}
sd = v.compression_dose(v.dose_from_peaks([40.0] * 5))
out["annex_c"] = {"sd": sd, "r": v.injury_risk(sd, start_age=20, years=20, days_per_year=120)}
print(json.dumps(out))
"""


def _half_sines(x: np.ndarray, fs: float, starts, amplitudes, length_s: float) -> None:
    n = int(length_s * fs)
    for k, a in zip(starts, amplitudes):
        x[k:k + n] += a * np.sin(np.pi * np.arange(n) / n)


def signals(seed: int = 7) -> dict:
    """SYNTHETIC test signals: name -> (acceleration [m/s^2], rate [Hz])."""
    rng = np.random.default_rng(seed)
    out = {}
    fs = 500.0
    x = np.zeros(int(60 * fs))
    times = np.cumsum(rng.uniform(1.5, 4.0, 30))
    times = times[times < 58]
    _half_sines(x, fs, (times * fs).astype(int), rng.uniform(2, 12, times.size), 0.08)
    out["shock train, 500 Hz"] = (x - x.mean(), fs)
    for fs, band, rms, n_shocks, peak, length_s, duration in ((256.0, 20, 0.8, 40, 15, 0.1, 300),
                                                             (1000.0, 30, 1.2, 30, 25, 0.05, 120)):
        n = int(duration * fs)
        x = signal.sosfilt(signal.butter(4, [0.5, band], "band", fs=fs, output="sos"), rng.standard_normal(n))
        x *= rms / x.std()
        _half_sines(x, fs, rng.integers(fs, n - fs, n_shocks), rng.uniform(-10 if fs < 500 else 5, peak, n_shocks),
                    length_s)
        out[f"random with shocks, {fs:g} Hz"] = (x - x.mean(), fs)
    x = np.zeros(2560)
    x[::400] = 60.0
    out["phonometry's test impulses, 256 Hz"] = (x, 256.0)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--phonometry-python", required=True, help="a Python with phonometry installed")
    args = ap.parse_args()
    sig = signals()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "signals.npz"
        np.savez(path, **{k: v[0] for k, v in sig.items()}, **{k + "__fs": v[1] for k, v in sig.items()})
        run = subprocess.run([args.phonometry_python, "-c", _PHONOMETRY, str(path)], capture_output=True, text=True,
                             check=True)
    phon = json.loads(run.stdout)
    exposure = spine.SpineExposure(daily_exposure_h=8.0, start_age_years=20, exposure_years=20, days_per_year=120)
    print(f"{'signal':36s} {'peaks ehm/phon':>15s} {'largest peak':>12s} {'diff':>9s} {'S_d [MPa]':>10s} {'diff':>9s}")
    for name, (x, fs) in sig.items():
        response = spine.lumbar_response(x, fs, remove_mean=False)  # phonometry takes the signal as it is
        r = spine.spinal_dose_from_lumbar(response.acc_mps2, response.fs_hz, exposure, x.size / fs)
        p = phon[name]
        print(f"{name:36s} {r.peaks_mps2.size:7d}/{p['peaks']:<7d} {r.largest_peak_mps2:12.4f} "
              f"{r.largest_peak_mps2 / p['peak_max'] - 1:+9.1e} {r.compressive_stress_mpa:10.5f} "
              f"{r.compressive_stress_mpa / p['sd'] - 1:+9.1e}")
    sd = exposure.m_z * spine.dose_from_peaks([40.0] * 5)
    print(f"Annex C example, 5 x 40 m/s^2: S_d {sd:.5f} MPa (phonometry {phon['annex_c']['sd']:.5f}), "
          f"R {spine.r_factor(sd, exposure):.5f} (phonometry {phon['annex_c']['r']:.5f})")


if __name__ == "__main__":
    main()
