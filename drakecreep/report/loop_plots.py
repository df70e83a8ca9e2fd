"""Plots of the servo-loop analysis: Bode, Nyquist, root loci, pole map (report units on the axes: Hz, N/um).

Each function draws from computed data (:mod:`drakecreep.servo.loops`, :mod:`drakecreep.servo.polemap`) and writes
one PNG; none of them computes a model.
"""

import math

import control  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from drakecreep.servo.loops import LOOPS  # noqa: E402
from drakecreep.servo.polemap import damping_width  # noqa: E402

__all__ = [
    "plot_bode",
    "plot_nyquist",
    "plot_gain_locus",
    "plot_parameter_loci",
    "plot_pole_map",
    "plot_step_and_feed",
]

_STYLE = {"continuous": dict(ls="--", lw=1.0), "sampled": dict(ls="-", lw=1.3)}
_COLOR = {"velocity": "C0", "position": "C3"}


def _grid(L, lo=0.1, dense_at=(), n=3000):
    """Log frequency grid (Hz) up to Nyquist (sampled) or 5 kHz, refined around ``dense_at`` (resonances,
    crossovers) so that sharp features are drawn as smooth curves."""
    top = 0.5 / L.dt if L.isdtime(strict=True) else 5e3
    f = np.logspace(math.log10(lo), math.log10(top * 0.999), n)
    extra = [fc * (1.0 + np.linspace(-0.1, 0.1, 4001)) for fc in dense_at if math.isfinite(fc) and lo < fc < top]
    return np.unique(np.concatenate([f, *extra])) if extra else f


def _resp(L, f):
    return np.asarray(control.frequency_response(L, 2 * np.pi * f).complex).reshape(-1)


def _phase_deg(r):
    """Unwrapped phase (deg), shifted by a multiple of 360 so that it starts in (-360, 0]."""
    p = np.degrees(np.unwrap(np.angle(r)))
    return p - 360.0 * math.ceil(p[0] / 360.0)


def _fmt(value, unit, digits=3):
    if isinstance(value, str) or value is None or not math.isfinite(value):
        return "inf" if value in ("inf", math.inf) else "n/a"
    return f"{value:.{digits}g} {unit}"


def plot_bode(analysis, path):
    """Bode plot of both loop gains, continuous (dashed) and sampled (solid).

    The margins of the configured controller are drawn where they are read: the phase margin as an arrow
    from -180 deg at the gain crossover, the gain margin as an arrow from 0 dB at the phase crossover, each
    labelled with its value; the crossovers are labelled in Hz.
    """
    fig, (axm, axp) = plt.subplots(2, 1, figsize=(10, 7.5), sharex=True, constrained_layout=True)
    main = "sampled" if analysis.sampled else "continuous"
    res = analysis.resonance_Hz
    phase_lo = -200.0
    for variant, loops in analysis.loops.items():
        for loop in LOOPS:
            L = loops[loop]
            m = analysis.margins[variant][loop]
            f = _grid(L, dense_at=(res, m["crossover_Hz"]))
            r = _resp(L, f)
            label = f"{loop} loop, {variant}"
            axm.semilogx(f, 20 * np.log10(np.abs(r)), color=_COLOR[loop], label=label, **_STYLE[variant])
            ph = _phase_deg(r)
            axp.semilogx(f, ph, color=_COLOR[loop], **_STYLE[variant])
            phase_lo = min(phase_lo, float(np.min(ph)))
            if variant != main:
                continue
            fc, pm = m["crossover_Hz"], m["phase_margin_deg"]
            if math.isfinite(fc):
                for ax in (axm, axp):
                    ax.axvline(fc, color=_COLOR[loop], lw=0.6, alpha=0.5)
                axm.annotate(f"{loop}: crossover {fc:.3g} Hz", (fc, 0), xytext=(4, 8 if loop == "velocity" else -14),
                             textcoords="offset points", color=_COLOR[loop], fontsize=8)
                if math.isfinite(pm):
                    axp.annotate("", xy=(fc, -180.0 + pm), xytext=(fc, -180.0),
                                 arrowprops=dict(arrowstyle="->", color=_COLOR[loop], lw=1.5))
                    axp.annotate(f"PM {pm:.1f} deg", (fc, -180.0 + pm / 2), xytext=(5, 0), textcoords="offset points",
                                 color=_COLOR[loop], fontsize=8, va="center")
            fp, gm = m["phase_crossover_Hz"], m["gain_margin_dB"]
            if fp is not None and math.isfinite(fp) and not isinstance(gm, str) and math.isfinite(gm):
                axm.annotate("", xy=(fp, 0.0), xytext=(fp, -gm),
                             arrowprops=dict(arrowstyle="->", color=_COLOR[loop], lw=1.5))
                axm.annotate(f"GM {gm:.1f} dB\nat {fp:.3g} Hz", (fp, -gm / 2), xytext=(5, 0),
                             textcoords="offset points", color=_COLOR[loop], fontsize=8, va="center")
                axp.axvline(fp, color=_COLOR[loop], lw=0.6, ls=":", alpha=0.6)
    axm.axhline(0, color="k", lw=0.6)
    axp.axhline(-180, color="k", lw=0.6)
    axp.set_ylim(max(phase_lo, -400.0) - 10.0, 60.0)
    axp.set_yticks(np.arange(-360, 61, 45))
    if math.isfinite(res):
        for ax in (axm, axp):
            ax.axvline(res, color="C2", ls=":", lw=1)
        axm.text(res, axm.get_ylim()[1], f" first mechanical resonance {res:.3g} Hz", color="C2", va="top", fontsize=8)
    axm.set_ylabel("|L| (dB)")
    axp.set_ylabel("phase of L (deg)")
    axp.set_xlabel("frequency (Hz)")
    axm.legend(fontsize=8, loc="lower left")
    axm.set_title(f"loop gains broken at the speed feedback (velocity) and the position feedback (position); "
                  f"margins of the {main} controller", fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_nyquist(analysis, path):
    """Nyquist curves of both loops near -1: the ``1/Ms`` circle, the gain-margin point on the negative real
    axis and the phase-margin point on the unit circle; a grid refined at the resonance and the crossover."""
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.6), constrained_layout=True)
    main = "sampled" if analysis.sampled else "continuous"
    t = np.linspace(0, 2 * np.pi, 400)
    for ax, loop in zip(axes, LOOPS):
        m = analysis.margins[main][loop]
        for variant, loops in analysis.loops.items():
            L = loops[loop]
            f = _grid(L, lo=0.01, dense_at=(analysis.resonance_Hz, m["crossover_Hz"], m["phase_crossover_Hz"] or math.nan),
                      n=6000)
            r = _resp(L, f)
            ax.plot(r.real, r.imag, color=_COLOR[loop], label=f"{variant}, f > 0", **_STYLE[variant])
            ax.plot(r.real, -r.imag, color=_COLOR[loop], alpha=0.3, **_STYLE[variant])
        ms = m["ms_peak"]
        ax.plot(-1 + np.cos(t) / ms, np.sin(t) / ms, color="0.5", lw=0.8, label=f"1/Ms circle (Ms = {ms:.2f})")
        ax.plot(np.cos(t), np.sin(t), color="0.8", lw=0.6, label="unit circle")
        ax.plot([-1], [0], "k+", ms=12, mew=2)
        ax.annotate("-1", (-1, 0), xytext=(-12, 6), textcoords="offset points", fontsize=9)
        gm = m["gain_margin_dB"]
        if not isinstance(gm, str) and math.isfinite(gm):
            x = -10 ** (-gm / 20)
            ax.plot([x], [0], "o", color=_COLOR[loop], mfc="none", ms=7, label=f"GM {gm:.1f} dB: -1/GM = {x:.3f}")
        pm = m["phase_margin_deg"]
        if math.isfinite(pm):
            ang = np.radians(-180.0 + pm)
            ax.plot([0, np.cos(ang)], [0, np.sin(ang)], color=_COLOR[loop], lw=0.8, ls=":")
            ax.plot([np.cos(ang)], [np.sin(ang)], "s", color=_COLOR[loop], mfc="none", ms=7, label=f"PM {pm:.1f} deg")
        ax.set_xlim(-2.5, 1.5)
        ax.set_ylim(-2.0, 2.0)
        ax.set_aspect("equal")
        ax.axhline(0, color="k", lw=0.4)
        ax.axvline(0, color="k", lw=0.4)
        ax.set_title(f"{loop} loop, zoom on -1 (margins of the {main} controller)", fontsize=9)
        ax.set_xlabel("Re L")
        ax.set_ylabel("Im L")
        ax.legend(fontsize=7.5, loc="lower right")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _dominant_box(poles, dt, f_max):
    """Axis limits around the closed-loop poles slower than ``f_max`` (Hz), with a margin; the s-plane box keeps
    the imaginary axis in view, the z-plane box the point z = 1."""
    s = np.log(poles.astype(complex)) / dt if dt else poles.astype(complex)
    keep = poles[np.abs(s) <= 2 * np.pi * f_max]
    if keep.size == 0:
        keep = poles
    anchor = 1.0 + 0j if dt else 0j
    pts = np.concatenate([keep, [anchor]])
    x0, x1 = pts.real.min(), pts.real.max()
    yabs = max(np.abs(pts.imag).max(), 0.25 * (x1 - x0), 1e-3)
    pad = 0.25 * max(x1 - x0, yabs)
    return (x0 - pad, x1 + pad), (-yabs - pad, yabs + pad)


def plot_gain_locus(analysis, path, factors=None):
    """Root locus of the velocity loop versus a factor on its PI gains (continuous s-plane, sampled z-plane).

    Each panel is zoomed to the dominant closed-loop poles (slower than twice the higher of the crossover and
    the screw's axial mode); an inset shows the full range.
    """
    factors = np.geomspace(0.05, 20, 240) if factors is None else np.asarray(factors)
    variants = list(analysis.loops)
    fig, axes = plt.subplots(1, len(variants), figsize=(6.5 * len(variants), 5.6), constrained_layout=True,
                             squeeze=False)
    for ax, variant in zip(axes[0], variants):
        L = analysis.loops[variant]["velocity"]
        m = analysis.margins[variant]["velocity"]
        pts = np.array([control.feedback(k * L, 1).poles() for k in factors])
        discrete = L.isdtime(strict=True)
        kk = np.repeat(factors, pts.shape[1])
        nominal = control.feedback(L, 1).poles()
        ol, z = L.poles(), L.zeros()
        inset = ax.inset_axes([0.08, 0.62, 0.32, 0.34])
        for target, small in ((ax, False), (inset, True)):
            sc = target.scatter(pts.real.ravel(), pts.imag.ravel(), c=np.log10(kk), s=2 if small else 5,
                                cmap="viridis", vmin=np.log10(factors[0]), vmax=np.log10(factors[-1]))
            target.plot(nominal.real, nominal.imag, "r^", ms=4 if small else 8, mfc="none",
                        label="closed loop, nominal gains")
            target.plot(ol.real, ol.imag, "kx", ms=4 if small else 7, label="open-loop poles")
            target.plot(z.real, z.imag, "ko", ms=3 if small else 6, mfc="none", label="zeros")
            if discrete:
                t = np.linspace(0, 2 * np.pi, 400)
                target.plot(np.cos(t), np.sin(t), color="0.5", lw=0.8)
            else:
                target.axvline(0, color="k", lw=0.6)
            if small:
                colorbar_source = sc
        if discrete:
            inset.set_xlim(-1.15, 1.15)
            inset.set_ylim(-1.15, 1.15)
            inset.set_aspect("equal")
            ax.set_xlabel("Re z")
            ax.set_ylabel("Im z")
        else:
            inset.set_xlim(-1500, 300)
            inset.set_ylim(-900, 900)
            ax.set_xlabel("Re s (1/s)")
            ax.set_ylabel("Im s (rad/s)")
        inset.set_title("full range", fontsize=7)
        inset.tick_params(labelsize=6)
        f_max = 2 * max(m["crossover_Hz"] if math.isfinite(m["crossover_Hz"]) else 0.0,
                        analysis.resonance_Hz if math.isfinite(analysis.resonance_Hz) else 0.0, 1.0)
        xlim, ylim = _dominant_box(nominal, L.dt if discrete else 0.0, f_max)
        ax.set_xlim(*xlim)
        ax.set_ylim(*ylim)
        fig.colorbar(colorbar_source, ax=ax, label="log10(gain factor on kv, ki)")
        ax.set_title(f"velocity loop, {variant} ({'z-plane' if discrete else 's-plane'}): zoom on the poles "
                     f"below {f_max:.3g} Hz", fontsize=9)
        ax.legend(fontsize=7, loc="lower left")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_parameter_loci(loci, path, labels=None, crossings=None):
    """Closed-loop poles versus physical parameters, one panel per locus from :func:`polemap.parameter_locus`.

    ``labels``: axis text per locus name; ``crossings``: text added to the friction-slope panel.
    """
    fig, axes = plt.subplots(1, len(loci), figsize=(5.4 * len(loci), 5), constrained_layout=True, squeeze=False)
    for ax, locus in zip(axes[0], loci):
        vals = locus["values"]
        color_val = np.log10(vals * (1e3 if locus["name"] == "feed" else 1.0))
        for v, poles in zip(color_val, locus["poles"]):
            sc = ax.scatter(poles.real, poles.imag, c=np.full(len(poles), v), s=6, cmap="plasma",
                            vmin=color_val.min(), vmax=color_val.max())
        ax.axvline(0, color="k", lw=0.6)
        ax.set_xlim(-600, 400)
        ax.set_ylim(-700, 700)
        ax.set_xlabel("Re s (1/s)")
        ax.set_ylabel("Im s (rad/s)")
        name = (labels or {}).get(locus["name"], locus["name"])
        fig.colorbar(sc, ax=ax, label=f"log10({name})")
        title = f"closed-loop poles vs {name}"
        if locus["name"] == "feed" and crossings:
            title += "\n" + crossings
        ax.set_title(title, fontsize=9)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_pole_map(pm, path):
    """Stiffness x (C + C1) plane: rightmost closed-loop pole, the linear boundaries, the paper's condition."""
    fig, ax = plt.subplots(figsize=(9, 8), constrained_layout=True)
    Kum = pm.stiffness * 1e-6
    X = np.broadcast_to(Kum, pm.damping.shape)
    lim = np.max(np.abs(pm.closed_loop))
    cf = ax.contourf(X, pm.damping, pm.closed_loop, levels=np.linspace(-lim, lim, 41), cmap="RdBu_r")
    fig.colorbar(cf, ax=ax, label="real part of the rightmost closed-loop pole (1/s); red = unstable")
    cs1 = ax.contour(X, pm.damping, pm.closed_loop, levels=[0.0], colors="k", linewidths=2)
    cs2 = ax.contour(X, pm.damping, pm.mechanism, levels=[0.0], colors="C2", linewidths=1.5, linestyles="--")
    ax.axhline(0.0, color="C1", lw=1.5, ls=":")
    kk = np.geomspace(pm.stiffness.min(), pm.stiffness.max(), 200)
    ax.plot(kk * 1e-6, pm.paper_boundary(kk), color="m", lw=2)
    handles = [
        plt.Line2D([], [], color="k", lw=2, label="linear stability boundary, whole servo loop (Drake linearization)"),
        plt.Line2D([], [], color="C2", lw=1.5, ls="--", label="linear boundary, paper mechanism (motor motion prescribed)"),
        plt.Line2D([], [], color="C1", lw=1.5, ls=":", label="C + C1 = 0 (paper eq. 2)"),
        plt.Line2D([], [], color="m", lw=2, label="paper creep condition D^2 = 4 pi zeta (above: no creep)"),
    ]
    if len(pm.sim_creep):
        c = pm.sim_creep
        ax.scatter(pm.sim_stiffness[c] * 1e-6, pm.sim_damping[c], marker="x", color="k", s=40, zorder=5)
        ax.scatter(pm.sim_stiffness[~c] * 1e-6, pm.sim_damping[~c], marker="o", facecolor="none", edgecolor="k",
                   s=40, zorder=5)
        handles += [
            plt.Line2D([], [], marker="x", color="k", ls="", label="simulated: creep (table sticks)"),
            plt.Line2D([], [], marker="o", mfc="none", color="k", ls="", label="simulated: steady sliding"),
        ]
    ax.plot([pm.nominal[0] * 1e-6], [pm.nominal[1]], "y*", ms=16, mec="k", zorder=6)
    handles.append(plt.Line2D([], [], marker="*", color="y", mec="k", ms=12, ls="", label="parameters used"))
    ax.set_xscale("log")
    # linear near zero, logarithmic beyond (the damping rows are even on it, polemap.damping_width): the paper's
    # curve sets the top at megagrams per second while the unstable band lies within a few 1e5 N s/m of zero
    width = damping_width((pm.damping.min(), pm.damping.max()))
    ax.set_yscale("asinh", linear_width=width)
    u0, u1 = np.arcsinh(pm.damping.min() / width), np.arcsinh(pm.damping.max() / width)
    ax.set_ylim(width * np.sinh(u0 - 0.02 * (u1 - u0)), pm.damping.max())
    ticks = [t for t in ax.get_yticks() if t == 0 or abs(t) >= 0.3 * width]  # none crowding the zero's label
    ax.set_yticks(ticks)
    ax.set_xlabel("axial stiffness K of the screw chain (N/um)")
    ax.set_ylabel("effective damping C + C1 (N s/m; linear near 0, logarithmic beyond)")
    ax.set_title(f"pole map at feed {pm.feed * 1e3:g} mm/s, M = {pm.mass:.4g} kg, Fs - Fc = {pm.friction_drop:.3g} N",
                 fontsize=9)
    ax.legend(handles=handles, fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2)
    del cs1, cs2
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def plot_step_and_feed(step, feed, path):
    """Two simulations: a speed step (table and motor speed vs reference) and a low-speed feed."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), constrained_layout=True)
    for ax, r, title in ((axes[0], step, "speed step"), (axes[1], feed, "low-speed feed")):
        t, s = r.time, r.signals
        ax.plot(t, s["v_ref"] * 1e3, "k--", lw=0.8, label="reference")
        ax.plot(t, s["motor_velocity"] * 1e3, color="0.6", lw=0.8, label="motor (at the table)")
        ax.plot(t, s["table_speed"] * 1e3, color="C0", lw=1.0, label="table")
        ax.set_ylabel("speed (mm/s)")
        ax.set_xlabel("time (s)")
        m = r.metrics
        extra = ""
        if m is not None:
            extra = (f": max fluctuation {m.max_fluctuation * 1e3:.3g} mm/s, stick {m.stick_fraction * 100:.1f} %, "
                     f"{m.stick_slip_cycles} stick-slip cycles")
        ax.set_title(f"{title}, {r.scenario.feed * 1e3:g} mm/s, load case {r.scenario.load_case}{extra}", fontsize=9)
        ax.legend(fontsize=8, loc="lower right")
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
