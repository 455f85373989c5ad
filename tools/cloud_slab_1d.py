#!/usr/bin/env python3
"""The clouds' lighting model in its own geometry: a plane-parallel slab, no air, a black
base, lit by a beam at cosine μ₀. What leaves its top per unit beam irradiance, averaged
over azimuth, by a 1D Monte Carlo (every order, the true dual-lobe phase) against the
renderer's model (render::volumes::light_sources with scene::clouds::two_stream): the
single scattering exact, the δ-Eddington two-stream's diffuse field I₀ + g′I₁μ scattered
towards the eye through the δ-scaled extinction (Toon et al. 1989's source-function
integration), and the beam's light in the forward peak scattered with Potter's truncated
phase min(p, p(θ_c)).

It separates the model's own error from the renderer's geometry and air
(docs/accuracy.md, "The cloud tops: the two-stream's angular shape"):

    python3 tools/cloud_slab_1d.py [--photons 300000]

numpy only. The phase (g 0.8 / −0.5, forward weight 0.8) and albedo (0.999) are the
cloud layers' defaults.
"""
from __future__ import annotations

import argparse

import numpy as np

G1, G2, W = 0.8, -0.5, 0.8  # the cloud layers' dual-lobe phase (scene::clouds::config)
OMEGA = 0.999  # their single-scattering albedo


def hg(g, c):
    """Henyey & Greenstein (1941), sr⁻¹."""
    return (1 - g * g) / (4 * np.pi * (1 + g * g - 2 * g * c) ** 1.5)


def phase(c):
    return W * hg(G1, c) + (1 - W) * hg(G2, c)


def hg_sample(g, u):
    s = (1 - g * g) / (1 - g + 2 * g * u)
    return (1 + g * g - s * s) / (2 * g)


def monte_carlo(tau_star, mu0, photons, bins, rng):
    """Radiance leaving the top per unit beam irradiance, mean over each μ bin and azimuth:
    (all orders, single scattering)."""
    mu = np.full(photons, -mu0)  # direction cosine from the upward vertical
    depth = np.zeros(photons)
    weight = np.ones(photons)
    order = np.zeros(photons, int)
    alive = np.ones(photons, bool)
    total = np.zeros(len(bins) - 1)
    single = np.zeros(len(bins) - 1)
    while alive.any():
        idx = np.nonzero(alive)[0]
        step = -np.log(rng.random(len(idx)))
        new = depth[idx] - mu[idx] * step
        top, base = new < 0, new > tau_star
        out = idx[top]
        total += np.histogram(mu[out], bins, weights=weight[out])[0]
        one = out[order[out] == 1]
        single += np.histogram(mu[one], bins, weights=weight[one])[0]
        alive[idx[top | base]] = False
        sc = idx[~(top | base)]
        depth[sc] = new[~(top | base)]
        weight[sc] *= OMEGA
        order[sc] += 1
        u = rng.random(len(sc))
        cos = np.where(rng.random(len(sc)) < W, hg_sample(G1, u), hg_sample(G2, u))
        phi = 2 * np.pi * rng.random(len(sc))
        m = mu[sc]
        mu[sc] = np.clip(
            m * cos + np.sqrt(np.maximum(0, 1 - m * m) * np.maximum(0, 1 - cos * cos)) * np.cos(phi),
            -1,
            1,
        )
    # N photons carry the flux μ₀; radiance = flux / (π (μ₂² − μ₁²)).
    norm = mu0 / photons / (np.pi * (bins[1:] ** 2 - bins[:-1] ** 2))
    return total * norm, single * norm


def two_stream(omega, g, tau, mu0, u):
    """δ-scaled two-stream (I₀, I₁) at relative depths u (scene::clouds::two_stream's
    flux_pairs and moments: Meador & Weaver 1980, Toon et al. 1989 Table 1, Eddington)."""
    g1 = (7 - omega * (4 + 3 * g)) / 4
    g2 = -(1 - omega * (4 - 3 * g)) / 4
    k = np.sqrt(max(g1 * g1 - g2 * g2, 1e-18))
    g3 = (2 - 3 * g * mu0) / 4
    g4 = 1 - g3
    a11, a12, a21, a22 = g1 + 1 / mu0, -g2, g2, -(g1 - 1 / mu0)
    r1, r2 = omega * g3, -omega * g4
    det = a11 * a22 - a12 * a21
    alpha, beta = (r1 * a22 - a12 * r2) / det, (a11 * r2 - a21 * r1) / det
    cp, cm = (g1 - k) / g2, (g1 + k) / g2
    et = np.exp(-k * tau)
    a, b = np.linalg.solve(
        np.array([[cp * et, cm], [1, et]]), np.array([-beta, -alpha * np.exp(-tau / mu0)])
    )
    t = u * tau
    grow, decay, beam = np.exp(k * (t - tau)), np.exp(-k * t), np.exp(-t / mu0)
    up = a * grow + b * decay + alpha * beam
    down = a * cp * grow + b * cm * decay + beta * beam
    return (up + down) / (2 * np.pi), 3 * (up - down) / (4 * np.pi)


def potter_cap(f):
    """p(θ_c) with 2π∫_{θ<θ_c}(p − p(θ_c)) dΩ = f (PhaseFunction::truncated_forward_value)."""

    def cut(c):
        s = np.linspace(np.log(1e-9), np.log(1 - c), 4000)
        e = np.exp(s)
        return 2 * np.pi * np.trapezoid((phase(1 - e) - phase(c)) * e, s)

    lo, hi = -1.0, 1.0
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if cut(mid) > f else (lo, mid)
    return phase(lo)


def model(tau_star, mu0, mus, peak=True):
    """The renderer's radiance leaving the top at cosines `mus` (azimuth mean): (all, single)."""
    g = W * G1 + (1 - W) * G2
    f = g * g
    scale = 1 - OMEGA * f
    omega_s, g_s = (1 - f) * OMEGA / scale, g / (1 + g)
    cap = potter_cap(f)
    n = 4000
    tau = (np.arange(n) + 0.5) / n * min(tau_star, 40.0)
    dt = tau[1] - tau[0]
    i0, i1 = two_stream(omega_s, g_s, scale * tau_star, mu0, tau / tau_star)
    phis = np.linspace(0, 2 * np.pi, 72, endpoint=False)
    total, single = [], []
    for mu in mus:
        cos = -mu * mu0 + np.sqrt((1 - mu * mu) * (1 - mu0 * mu0)) * np.cos(phis)
        ss = OMEGA * phase(cos).mean() * np.sum(np.exp(-tau / mu0 - tau / mu)) * dt / mu
        source = OMEGA * (1 - f) * (i0 + g_s * i1 * mu)
        if peak:
            kept = np.minimum(phase(cos), cap).mean()
            source = source + OMEGA * kept * (np.exp(-scale * tau / mu0) - np.exp(-tau / mu0))
        diffuse = np.sum(source * np.exp(-scale * tau / mu)) * dt / mu
        total.append(ss + diffuse)
        single.append(ss)
    return np.array(total), np.array(single)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--photons", type=int, default=300_000)
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    bins = np.linspace(0.2, 1.0, 9)
    fine = np.linspace(0.2, 1.0, 161)
    fine = 0.5 * (fine[1:] + fine[:-1])

    def bin_mean(v):  # μ-weighted (flux) mean over each bin
        return np.array(
            [np.sum((v * fine)[(fine >= a) & (fine < b)]) / np.sum(fine[(fine >= a) & (fine < b)])
             for a, b in zip(bins[:-1], bins[1:])]
        )

    print("| slab τ | sun zenith | view μ | MC | MC single | model | model − MC | without the peak's light |")
    print("|---|---|---|---|---|---|---|---|")
    for tau_star, zenith in [(5, 30), (5, 70), (20, 30), (20, 70)]:
        mu0 = np.cos(np.radians(zenith))
        mc, mc1 = monte_carlo(tau_star, mu0, args.photons, bins, rng)
        m, _ = model(tau_star, mu0, fine)
        m0, _ = model(tau_star, mu0, fine, peak=False)
        m, m0 = bin_mean(m), bin_mean(m0)
        for i, mu in enumerate(0.5 * (bins[1:] + bins[:-1])):
            print(
                f"| {tau_star} | {zenith}° | {mu:.2f} | {mc[i]:.4f} | {mc1[i]:.4f} | {m[i]:.4f} "
                f"| {100 * (m[i] / mc[i] - 1):+.1f} % | {100 * (m0[i] / mc[i] - 1):+.1f} % |"
            )


if __name__ == "__main__":
    main()
