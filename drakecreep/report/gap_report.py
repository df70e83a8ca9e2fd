"""Self-contained HTML report of a gap diagnosis (plots embedded as base64 PNG) and its JSON form."""

from __future__ import annotations

import base64
import html
import io
import json

import numpy as np

from drakecreep.files import to_jsonable

__all__ = ["to_json_dict", "write_report"]


def _clean(obj):
    """The result without private keys and raw spectra, as JSON types."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items() if not str(k).startswith("_") and k != "spectra"}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    return to_jsonable(obj)


def to_json_dict(result):
    """JSON-ready form of a :func:`drakecreep.gap.diagnosis.diagnose` result (spectra arrays dropped).

    Keys include ``where`` (regime shares and order peaks per signal), ``ranking`` (effect, score,
    held-out gap before/after, fitted parameters), ``unexplained_share``, ``claimed``, ``shrink``.
    """
    res = dict(result)
    if "where" in res:
        res["where"] = {k: v for k, v in res["where"].items() if k != "spectra"}
    return _clean(res)


def _png(fig):
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _plots(result):
    import matplotlib.pyplot as plt

    out = []
    where = result.get("where")
    if where:
        regimes = list(next(iter(where["regimes"].values())).keys())
        fig, ax = plt.subplots(figsize=(7, 3))
        width = 0.2
        for i, sig in enumerate(("speed", "position", "force")):
            shares = [100 * where["regimes"][sig][r]["energy_share"] for r in regimes]
            ax.bar(np.arange(len(regimes)) + (i - 1) * width, shares, width, label=f"{sig} residual energy")
        ax.bar(np.arange(len(regimes)) + 2 * width, [100 * where["regimes"]["speed"][r]["time_share"]
                                                   for r in regimes], width, color="0.7", label="time")
        ax.set_xticks(np.arange(len(regimes)), [r.replace("_", " ") for r in regimes])
        ax.set_ylabel("share [%]")
        ax.legend(fontsize=7)
        ax.set_title("Held-out residual energy by time regime")
        out.append(("Where: time regimes", _png(fig)))
        spectra = where.get("spectra", {})
        fig, axes = plt.subplots(1, 3, figsize=(10, 3))
        for ax, sig in zip(axes, ("speed", "position", "force")):
            for axis, style in (("screw", "-"), ("motor", "--")):
                if axis in spectra.get(sig, {}):
                    o, p = spectra[sig][axis]
                    ax.semilogy(o, p, style, label=axis)
            ax.set_xlim(0, 10)
            ax.set_xlabel("order [cycles / rev]")
            ax.set_title(f"{sig} residual vs angle", fontsize=9)
            ax.legend(fontsize=7)
        out.append(("Where: order spectra (residual resampled against screw / motor angle)", _png(fig)))
        fig, axes = plt.subplots(1, 3, figsize=(10, 3))
        for ax, sig in zip(axes, ("speed", "position", "force")):
            if "time" in spectra.get(sig, {}):
                f, p = spectra[sig]["time"]
                ax.semilogy(f[1:], p[1:])
            ax.set_xlabel("frequency [Hz]")
            ax.set_title(f"{sig} residual vs time", fontsize=9)
        out.append(("Where: time spectra", _png(fig)))
        fig, axes = plt.subplots(1, 3, figsize=(10, 3))
        for ax, key, scale, unit in zip(axes, ("speed", "position", "load"), (1e3, 1e3, 1.0), ("mm/s", "mm", "N")):
            rows = where["map"]["speed"][key]
            centers = [scale * 0.5 * (r["lo"] + r["hi"]) for r in rows]
            ax.plot(centers, [1e3 * r["rms"] for r in rows], "o-")
            ax.set_xlabel(f"{key} [{unit}]")
            ax.set_ylabel("speed residual RMS [mm/s]")
        out.append(("Where: operating map (speed residual)", _png(fig)))
    gb, ga = result.get("_gap_before"), result.get("_gap_after")
    if gb:
        fig, axes = plt.subplots(3, 1, figsize=(9, 6), sharex=True)
        p0 = gb["per_run"][0]
        p1 = ga["per_run"][0] if ga else None
        for ax, key, scale, unit in zip(axes, ("e_speed", "e_position", "e_force"), (1e3, 1e6, 1.0),
                                        ("mm/s", "um", "N")):
            ax.plot(p0["t"], scale * p0[key], lw=0.6, label="nominal")
            if p1 is not None:
                ax.plot(p1["t"], scale * p1[key], lw=0.6, label="with " + "+".join(result["claimed"]))
            ax.set_ylabel(f"{key[2:]} [{unit}]")
            ax.legend(fontsize=7)
        axes[-1].set_xlabel("time [s]")
        out.append(("Held-out residuals of the closed-loop replay (first held-out run)", _png(fig)))
    if result.get("ranking"):
        fig, ax = plt.subplots(figsize=(7, 3))
        names = [r["effect"] for r in result["ranking"]]
        ax.barh(names[::-1], [100 * r["gain"] for r in result["ranking"]][::-1])
        ax.set_xlabel("held-out residual energy removed [%]")
        ax.set_title("Which effect: held-out gain (ranking by penalized score)")
        out.append(("Which: effect ranking", _png(fig)))
    return out


def _table(rows, header):
    h = "".join(f"<th>{html.escape(c)}</th>" for c in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><tr>{h}</tr>{body}</table>"


def _fmt(x, digits=4):
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:.{digits}g}"
    return str(x)


def write_report(result, out_dir, title="Sim-to-real gap diagnosis"):
    """Write ``diagnosis.html`` and ``diagnosis.json`` into ``out_dir``.

    Returns
    -------
    tuple of pathlib.Path
        ``(html_path, json_path)``.
    """
    from pathlib import Path

    from drakecreep.files import OutputSet

    out = Path(out_dir)
    outset = OutputSet(out, "manifest.json").start()  # one set: manifest.json written last names its files
    data = to_json_dict(result)
    json_path = outset.write_text("diagnosis.json", json.dumps(data, indent=1))
    parts = [f"<h1>{html.escape(title)}</h1>", "<h2>Answer</h2><ul>"]
    parts += [f"<li>{html.escape(s)}</li>" for s in result.get("summary", [])]
    parts.append("</ul>")
    nom = result["nominal"]
    parts.append("<h2>Nominal rigid model (fitted on the training runs)</h2>")
    parts.append(_table([[k, _fmt(v), _fmt(nom["std"][k])] for k, v in nom["params"].items()],
                        ["parameter", "value", "std"]))
    rows = []
    for r in result.get("ranking", []):
        rr = r.get("replay_rms", {}).get("after", {})
        params = "; ".join(f"{k.split('.', 1)[-1]}={_fmt(v['value'])}"
                           + (f"±{_fmt(v['std'], 2)}" if v.get("std") is not None else "")
                           for k, v in r["params"].items())
        rows.append([r["effect"], f"{r['score']:+.1f}", f"{100 * r['gain']:.1f}",
                     f"{r['idim_rms_N']['before']:.3g} -> {r['idim_rms_N']['after']:.3g}",
                     _fmt(rr.get("speed_mm_s")), _fmt(rr.get("position_um")), params, r["signature"]])
    parts.append("<h2>Which effect: ranking (held-out score, negative = evidence)</h2>")
    parts.append(_table(rows, ["effect", "score", "held-out gain [%]", "held-out IDIM RMS [N]",
                               "replay speed RMS after [mm/s]", "replay position RMS after [um]",
                               "fitted parameters", "signature"]))
    if "pair" in result:
        parts.append(f"<p>Pair: {html.escape(result['pair']['effect'])} (incremental score "
                     f"{result['pair']['score']:+.1f}).</p>")
    if "shrink" in result:
        b, a = result["shrink"]["before"], result["shrink"]["after"]
        parts.append("<h2>How far it shrinks (held-out runs, closed-loop replay)</h2>")
        parts.append(_table([[k, _fmt(b[k]), _fmt(a.get(k))] for k in b], ["RMS", "nominal", result["shrink"]["model"]]))
    parts.append(f"<p>Unexplained share of the held-out inverse-dynamics residual energy: "
                 f"{100 * result['unexplained_share']:.1f} %.</p>")
    if "where" in result:
        w = result["where"]
        rows = []
        for sig in ("speed", "position", "force"):
            for reg, v in w["regimes"][sig].items():
                rows.append([sig, reg, f"{100 * v['energy_share']:.1f}", f"{100 * v['time_share']:.1f}"])
        parts.append("<h2>Where: residual energy by regime</h2>")
        parts.append(_table(rows, ["signal", "regime", "energy [%]", "time [%]"]))
        rows = [[sig, ax, _fmt(o.get("peak_order")), f"{100 * o.get('peak_share', 0):.1f}", _fmt(o.get("peak_ratio"))]
                for sig, d in w["orders"].items() for ax, o in d.items()]
        parts.append("<h2>Where: order peaks</h2>")
        parts.append(_table(rows, ["signal", "axis", "peak order", "peak share [%]", "peak / median PSD"]))
        if "whiteness" in w:
            wh = w["whiteness"]
            parts.append(f"<p>Whiteness of the held-out inverse-dynamics residual: Ljung-Box Q = {wh['ljung_box_q']:.1f}, "
                         f"p = {wh['ljung_box_p']:.3g}; max |cross-correlation with u| = {wh['max_abs_xcorr']:.3f} "
                         f"(95 % band {wh['xcorr_bound']:.3f}).</p>")
    for caption, png in _plots(result):
        parts.append(f"<h3>{html.escape(caption)}</h3><img src='data:image/png;base64,{png}'/>")
    doc = ("<!DOCTYPE html><html><head><meta charset='utf-8'><title>" + html.escape(title) + "</title>"
           "<style>body{font-family:sans-serif;max-width:1100px;margin:auto}table{border-collapse:collapse}"
           "td,th{border:1px solid #ccc;padding:2px 6px;font-size:12px}</style></head><body>"
           + "\n".join(parts) + "</body></html>")
    html_path = outset.write_text("diagnosis.html", doc)
    outset.commit(dict(report=title, html="diagnosis.html", json="diagnosis.json"))
    return html_path, json_path
