"""Results out where the user works: pandas DataFrames, xarray Datasets and the short tables a notebook shows.

The result classes (:class:`ehm.RunResult`, :class:`ehm.FrfTable`, :class:`ehm.Assessment`, the locking study's
:class:`ehm.analysis.study.LockingStudy`, and :func:`ehm.interfaces.batch.read_results`) shape their own data into named
columns;
this module only turns those columns into a DataFrame (with the run's description and route in
``DataFrame.attrs``), labelled arrays into an xarray Dataset, and a few figures into the HTML table of their
``_repr_html_``.  It is the one door for pandas and xarray going out, as :mod:`ehm.inputs.readers` is for data coming
in; it stands on the bottom floors (it imports only ``ehm.errors``), so every result module can reach it.
Conventions of every frame: long (tidy) where the values share a unit, one column per quantity otherwise; units
in the column names (``acc_mps2``, ``freq_hz``), or in a ``unit`` column beside a ``value`` column that mixes
them; labels (location, axis, ...) as pandas categoricals in the order ehm uses.
"""

from __future__ import annotations

import html

import numpy as np

from ..errors import InputError

__all__ = ["frame", "dataset", "html_table", "plain_attrs"]


def plain_attrs(attrs: dict) -> dict:
    """``attrs`` with tuples and lists of names joined by ``+`` (``"none"`` when empty) and None dropped, so
    that they survive pandas' copies and an xarray file (netCDF takes strings and numbers only)."""
    out = {}
    for key, value in attrs.items():
        if value is None:
            continue
        if isinstance(value, (tuple, list)) and all(isinstance(v, str) for v in value):
            value = "+".join(value) or "none"
        out[key] = value
    return out


def frame(columns: dict, attrs: dict, labels: dict | None = None):
    """A DataFrame of ``columns`` (name -> equal-length array, in order), ``attrs`` set (:func:`plain_attrs`);
    ``labels``: column -> the order of its values, made an ordered categorical (values outside the order
    become a category after it)."""
    import pandas as pd

    df = pd.DataFrame({k: np.asarray(v) for k, v in columns.items()})
    for col, order in (labels or {}).items():
        seen = list(dict.fromkeys(df[col].tolist()))
        categories = list(order) + [v for v in seen if v not in order]
        df[col] = pd.Categorical(df[col], categories=categories, ordered=True)
    df.attrs.update(plain_attrs(attrs))
    return df


def _xarray(what: str):
    try:
        import xarray
    except ImportError:
        raise InputError(f"{what} needs xarray: pip install 'ehm[xarray]' (or pip install xarray), or use "
                         "to_dataframe().") from None
    return xarray


def dataset(variables: dict, coords: dict, attrs: dict, what: str = "to_xarray()"):
    """An xarray Dataset: ``variables`` name -> (dims, array, unit), ``coords`` name -> values; the unit goes to
    each variable's ``units`` attribute, ``attrs`` (:func:`plain_attrs`) to the Dataset's.  Without xarray: one
    sentence naming the extra to install."""
    xr = _xarray(what)
    data = {name: xr.Variable(dims, values, attrs={"units": unit}) for name, (dims, values, unit) in variables.items()}
    return xr.Dataset(data, coords=coords, attrs=plain_attrs(attrs))


def _cell(value, tag: str = "td") -> str:
    if isinstance(value, float):
        text = "" if not np.isfinite(value) else f"{value:.4g}"
    else:
        text = str(value)
    return f"<{tag}>{html.escape(text)}</{tag}>"


def html_table(title: str, facts: dict, header: list, rows: list) -> str:
    """A notebook's short display of a result: ``title``, the ``facts`` of what was run (label -> text, one
    line each) and a table of headline figures (``header``, ``rows`` of values; floats to 4 significant
    digits, NaN empty).  Everything is escaped."""
    lines = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th>{_cell(v)}</tr>"
                    for k, v in facts.items() if v not in (None, ""))
    head = "<tr>" + "".join(_cell(h, "th") for h in header) + "</tr>"
    body = "".join("<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in rows)
    return (f"<div><p><b>{html.escape(title)}</b></p><table>{lines}</table>"
            f"<table>{head}{body}</table></div>")
