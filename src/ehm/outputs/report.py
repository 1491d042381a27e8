"""A one-page, self-contained HTML report of an assessment (figures embedded, no tool needed to read it)."""

from __future__ import annotations

import base64
import html
from pathlib import Path

from ..files import write_text_atomic

#: The documentation pages the report points to: (page in the documentation's source, what it explains).
DOC_PAGES = (("user_guide/drives.md", "drives and their assessment: what each figure means"),
             ("user_guide/measured_logs.md", "measured logs: channels, units, the cut, the warnings"),
             ("model.md", "the model: its limits and the sources of its parameters"),
             ("validation.md", "the person against the standards and the paper"))


def _docs_root() -> Path | None:
    """The documentation's source folder when ehm runs from its source tree (an editable install), else None."""
    root = Path(__file__).resolve().parents[3] / "docs"
    return root if (root / "index.md").is_file() else None


def _docs_html() -> str:
    """The report's pointers to the documentation: links to its pages where they are on this machine (ehm run from
    its source tree), else the pages by name."""
    root = _docs_root()
    items = []
    for page, what in DOC_PAGES:
        target = None if root is None else root / page
        name = html.escape(f"docs/{page}")
        link = (f'<a href="{html.escape(target.as_uri())}">{name}</a>' if target is not None and target.is_file()
                else f"<code>{name}</code>")
        items.append(f"<li>{link}: {html.escape(what)}</li>")
    return ("<h2>Documentation</h2>\n<ul>" + "".join(items) + "</ul>\n<p class=\"note\">The pages of ehm's "
            "documentation (in its source, <code>docs/</code>; also <code>help(ehm)</code> and "
            "<code>ehm COMMAND --help</code>).</p>\n")


def _messages_html(summary: dict) -> str:
    """The route line and every warning the console printed, as the console printed them."""
    lines = []
    route = summary.get("route") or {}
    if route.get("summary_line"):
        line = str(route["summary_line"])
        line = line[len("route: "):] if line.startswith("route: ") else line
        lines.append(f"<p><b>Route:</b> {html.escape(line)}</p>")
    warnings = summary.get("warnings") or []
    if warnings:
        lines.append("<h2>Warnings</h2>\n<ul>" + "".join(f"<li>{html.escape(str(w))}</li>" for w in warnings)
                     + "</ul>")
    return "\n".join(lines) + ("\n" if lines else "")


def _img(path: Path) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f'<img alt="{html.escape(Path(path).stem)}" src="data:image/png;base64,{data}">'


def _misc_html(summary: dict) -> str:
    """The predicted MISC rating of an assessment's summary (none for a summary without it)."""
    sick = summary["sickness"]
    if "final_misc" not in sick.get("head", {}):
        return ""
    whose = (summary.get("sickness_misc_params") or {}).get("whose", "group")
    return (f"<p>Predicted MISC rating (0-10, accumulation model, {html.escape(whose)} parameters) at the end: "
            f"<b>{sick['head']['final_misc']:.2f}</b> from the head's motion (highest "
            f"{sick['head']['max_misc']:.2f}), {sick['seat']['final_misc']:.2f} for a head fixed to the seat.</p>\n")


def _iso2631_5_html(section: dict | None) -> str:
    """The ISO 2631-5 section of the report: one row per route that was computed."""
    if not section:
        return ""
    e = section["exposure"]
    rows = []
    for name, label in (("standard_route", "standard's transfer function, from the seat"),
                        ("model_route", "body model's lumbar point")):
        v = section.get(name)
        if v:
            rows.append(f"<tr><th>{label}</th><td>{v['lumbar_peak_max_mps2']:.3g}</td><td>{v['lumbar_peak_count']}</td>"
                        f"<td>{v['dose_dz_mps2']:.3g}</td><td>{v['daily_dose_dzd_mps2']:.3g}</td>"
                        f"<td><b>{v['daily_compressive_stress_sd_mpa']:.3g}</b></td><td><b>{v['r_factor']:.3g}</b></td>"
                        f"<td>{100 * v['injury_probability']:.2g} %</td></tr>")
    r10, r50, r90 = section["standard_route"]["r_for_risk_10_50_90_pct"]
    differ = f"<p>{html.escape(section['routes_differ'])}</p>" if section.get("routes_differ") else ""
    return f"""<h2>Spinal dose (ISO 2631-5)</h2>
<table><tr><th>route</th><th>largest lumbar peak</th><th>peaks</th><th>D<sub>z</sub></th><th>D<sub>zd</sub></th>
<th>S<sub>d</sub> [MPa]</th><th>R</th><th>P</th></tr>
{''.join(rows)}</table>{differ}
<p class="note">Lumbar peaks, D<sub>z</sub> and D<sub>zd</sub> in m/s²: the positive peaks of the lumbar spine's
vertical acceleration response (ISO 2631-5:2018 Formula 1 applied to the seat's vertical acceleration, mean removed),
their dose over the drive and over a day of {e['daily_exposure_h']:g} h. S<sub>d</sub>: daily compressive stress;
R: over {e['exposure_years']} years from the age of {e['start_age_years']:g}, {e['days_per_year']:g} days a year,
the standard's {'82 kg man' if e['sex'] == 'male' else '64 kg woman'}; R {r10:g}, {r50:g} and {r90:g} mean a 10, 50
and 90 % probability of an adverse health effect (Annex C); P: the probability of a lumbar injury.</p>
"""


def write_report(summary: dict, figures: dict, path: Path | str, title: str = "Motion comfort assessment") -> None:
    """Write ``path`` (HTML) from an assessment summary (``Assessment.summary()``) and figure files: the figures, the
    route line and the warnings the console printed (``summary["warnings"]``, as ``ehm assess`` records them), and
    links to the documentation (:data:`DOC_PAGES`)."""
    locs = summary["locations"]
    rows = []
    for loc, v in locs.items():
        ax = v["axes"]
        seat = v.get("seat_value_total_pct")
        rows.append(
            "<tr>" + f"<th>{loc}</th>" + "".join(f"<td>{ax[a]['a_w_mps2']:.3f}</td>" for a in "xyz")
            + f"<td><b>{v['total_value_mps2']:.3f}</b></td><td>{html.escape(v['comfort_reaction'])}</td>"
            + f"<td>{ax['z']['vdv_mps175']:.3f}</td><td>{max(ax[a]['mtvv_mps2'] for a in 'xyz'):.3f}</td>"
            + f"<td>{v['msdv_z_mps15']:.3f}</td><td>{'' if seat is None else f'{seat:.0f} %'}</td></tr>")
    sick = summary["sickness"]
    band = summary.get("input_band_hz")
    outside = {w: v for w, v in summary.get("band_outside_share", {}).items() if v > 0}
    band_line = "" if not band else (
        f"<p><b>Band of the input:</b> {band[0]:.3g} to {band[1]:.3g} Hz (1/duration to the log's Nyquist "
        "frequency or the resampling's pass band); "
        + ("outside it lies " + ", ".join(f"{100 * v:.1f} % of {w}'s power" for w, v in outside.items())
           + " (|W(f)|² on a log-frequency axis): the weighted values miss that part." if outside
           else "it covers the Wd, Wk (0.5-80 Hz) and Wf (0.08-0.63 Hz) bands whole.") + "</p>")
    cut = summary.get("handling_cut")
    handling_line = f"<p><b>Handled logger:</b> {html.escape(cut['note'])}</p>" if cut else ""
    disp = summary.get("body_displacement_max_m", {})
    body = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>
body {{ font-family: sans-serif; max-width: 1100px; margin: 1.5em auto; color: #222; }}
table {{ border-collapse: collapse; margin: 0.8em 0; }} \
th, td {{ border: 1px solid #bbb; padding: 3px 8px; text-align: right; }}
th {{ background: #f0f0f0; }} img {{ max-width: 100%; margin: 0.4em 0; }} .note {{ color: #555; font-size: 0.9em; }}
</style></head><body>
<h1>{html.escape(title)}</h1>
<p><b>Drive:</b> {html.escape(summary['input'])} ({summary['duration_s']:.0f} s, \
simulated in {summary['wall_s']:.0f} s).<br>
<b>Person:</b> ehm seated human model, parameters: {html.escape(str(summary.get('params', 'default')))};
locked joints: {html.escape(', '.join(summary.get('locked', [])) or 'none')}\
{html.escape(' (' + summary['scaled'] + ')' if summary.get('scaled') else '')}.
Seat accelerations in seat axes.</p>
{handling_line}
{_messages_html(summary)}<h2>Comfort (ISO 2631-1)</h2>
<table><tr><th>location</th><th>a<sub>w,x</sub></th><th>a<sub>w,y</sub></th><th>a<sub>w,z</sub></th>
<th>total value a<sub>v</sub></th><th>comfort reaction</th><th>VDV<sub>z</sub></th><th>MTVV (max axis)</th>
<th>MSDV<sub>z</sub></th><th>SEAT (a<sub>v</sub>)</th></tr>
{''.join(rows)}</table>
{band_line}
<p class="note">a<sub>w</sub>, a<sub>v</sub>, MTVV in m/s²; VDV in m/s<sup>1.75</sup>; MSDV in m/s<sup>1.5</sup>.
Weightings: Wd (x, y), Wk (z), Wf for MSDV; total value with k = 1 (comfort, seated). SEAT: body over seat.
Comfort reactions: ISO 2631-1 Annex C bands for public transport.</p>
<h2>Motion sickness</h2>
<p>Predicted motion sickness incidence at the end of the drive (subjective vertical conflict model):
<b>{sick['head']['final_msi_percent']:.2f} %</b> from the head's motion,
{sick['seat']['final_msi_percent']:.2f} % for a head fixed to the seat.</p>
{_misc_html(summary)}
{_iso2631_5_html(summary.get("iso2631_5"))}<h2>Figures</h2>
{''.join(_img(p) for p in figures.values())}
<h2>Body motion</h2>
<p>Largest displacement from the settled posture [mm]:
{', '.join(f"{k} ({', '.join(f'{1000 * x:.0f}' for x in v)})" for k, v in disp.items())} (x, y, z).</p>
{_docs_html()}<p class="note">Generated by ehm.</p>
</body></html>
"""
    write_text_atomic(path, body)
