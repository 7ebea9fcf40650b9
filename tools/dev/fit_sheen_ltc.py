"""Fits the table of gridtrace's microfibre sheen: Zeltner, Burley & Chiang 2022,
"Practical Multiple-Scattering Sheen Using Linearly Transformed Cosines" (SIGGRAPH
talk), the sheen of Blender's Principled BSDF.

The reference is the talk's volumetric layer: a slab of unit optical thickness
(density 1, albedo 1) of fibres standing along the normal, an SGGX microflake medium
(Heitz et al. 2015) with S = diag(1, 1, σ²), σ = α², and the specular microflake phase
function. A path enters from the top and either leaves the top (reflected), leaves the
bottom (lost), or is counted by its direction after its 16th scattering, as the talk's
reference counts it.

For each (μi, α) on the talk's 32 × 32 grid (both linspace(0, 1, 32), clamped to 0.01)
the script random-walks paths, takes the reflectance R and a 32 × 32 histogram of the
cosine-weighted BRDF over (θo, φo ∈ [0, π]) and fits the inverse LTC matrix
[[a, 0, b], [0, a, 0], [0, 0, 1]] to the histogram (L3 loss, Nelder–Mead, warm-started
from the next rougher entry), as the talk describes. It writes
`src/render/bsdf/sheen_table.rs`.

Needs numpy and scipy; run: python tools/dev/fit_sheen_ltc.py [--paths N]
(2 cores, 2^21 paths per entry: about 20 minutes).
"""

import argparse
import multiprocessing
import pathlib

import numpy as np
from scipy.optimize import minimize

RES = 32
MUS = np.maximum(0.01, np.linspace(0.0, 1.0, RES))
ALPHAS = np.maximum(0.01, np.linspace(0.0, 1.0, RES))
MAX_SCATTERINGS = 16
CHUNK = 1 << 18
THETA_BINS = (np.arange(RES) + 0.5) / RES * 0.5 * np.pi
PHI_BINS = (np.arange(RES) + 0.5) / RES * np.pi


def projected_area(d, s_zz):
    """σ(ω) = sqrt(ωᵀ S ω) for S = diag(1, 1, s_zz)."""
    return np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2 + s_zz * d[:, 2] ** 2)


def sample_flake_normal(wi, sqrt_s_zz, rng):
    """A visible microflake normal for unit directions `wi` (rows). SGGX's ellipsoid is
    xᵀ S x = 1 (its projected area is ∝ sqrt(ωᵀ S ω)), i.e. x = S^-½ u for u on the unit
    sphere: seen along wi it is the unit sphere seen along S^½ wi, so a uniform point of
    that sphere's projected disk gives u, and the normal S x is ∝ S^½ u (Heitz et al.
    2015, §4)."""
    scale = np.array([1.0, 1.0, sqrt_s_zz])
    w = wi * scale
    w /= np.linalg.norm(w, axis=1, keepdims=True)
    # An orthonormal basis (t1, t2, w) per row.
    helper = np.where(np.abs(w[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    t1 = np.cross(helper, w)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(w, t1)
    r = np.sqrt(rng.random(len(wi)))
    phi = 2.0 * np.pi * rng.random(len(wi))
    x, y = r * np.cos(phi), r * np.sin(phi)
    z = np.sqrt(np.maximum(0.0, 1.0 - r * r))
    u = x[:, None] * t1 + y[:, None] * t2 + z[:, None] * w
    m = u * scale
    return m / np.linalg.norm(m, axis=1, keepdims=True)


def walk(mu, alpha, n, rng):
    """Directions of the paths, of `n` entering at cos θ = mu, that the layer reflects."""
    s_zz = alpha**4
    sqrt_s_zz = alpha**2
    sin = np.sqrt(1.0 - mu * mu)
    d = np.tile([-sin, 0.0, -mu], (n, 1))  # propagation direction
    depth = np.zeros(n)  # 0 at the top, 1 at the bottom
    out = []
    for scattering in range(MAX_SCATTERINGS):
        dist = -np.log1p(-rng.random(len(d))) / projected_area(d, s_zz)
        depth = depth - dist * d[:, 2]
        top = depth < 0.0
        out.append(d[top])
        inside = (~top) & (depth <= 1.0)
        d, depth = d[inside], depth[inside]
        if len(d) == 0:
            break
        wi = -d
        m = sample_flake_normal(wi, sqrt_s_zz, rng)
        d = 2.0 * np.sum(m * wi, axis=1, keepdims=True) * m - wi
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        if scattering == MAX_SCATTERINGS - 1:
            out.append(d[d[:, 2] > 0.0])
    return np.concatenate(out)


def measure(job):
    """Reflectance and cosine-weighted BRDF histogram of one table entry."""
    i_mu, i_alpha, paths = job
    rng = np.random.default_rng([i_mu, i_alpha])
    hist = np.zeros((RES, RES))
    reflected = 0
    for _ in range(paths // CHUNK):
        wo = walk(MUS[i_mu], ALPHAS[i_alpha], CHUNK, rng)
        reflected += len(wo)
        theta = np.arccos(np.clip(wo[:, 2], -1.0, 1.0))
        phi = np.abs(np.arctan2(wo[:, 1], wo[:, 0]))  # mirrored onto [0, π]
        h, _, _ = np.histogram2d(
            theta,
            phi,
            bins=[RES, RES],
            range=[[0.0, 0.5 * np.pi], [0.0, np.pi]],
            weights=1.0 / np.maximum(np.sin(theta), 1e-6),
        )
        hist += h
    # Samples per solid angle: a bin covers 2·sin θ·Δθ·Δφ (both halves of φ).
    hist *= RES * RES / (np.pi**2 * paths)
    # Near the normal the φ bins split one direction: average them.
    hist[0, :] = hist[0, :].mean()
    return i_mu, i_alpha, reflected / paths, hist


def ltc(reflectance, a, b):
    """The cosine-weighted LTC BRDF R·D(M⁻¹ω)·|M⁻¹|/|M⁻¹ω|³ at the histogram's bin
    centres, M⁻¹ = [[a, 0, b], [0, a, 0], [0, 0, 1]]."""
    theta, phi = np.meshgrid(THETA_BINS, PHI_BINS, indexing="ij")
    x = np.sin(theta) * np.cos(phi)
    y = np.sin(theta) * np.sin(phi)
    z = np.cos(theta)
    len2 = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return reflectance * z * (a / len2) ** 2 / np.pi


def fit(reflectance, hist):
    """Fits (a, b) per entry; entries with R < 3·10⁻⁶ keep a = 0 (no sheen)."""
    table = np.zeros((RES, RES, 3))
    table[:, :, 2] = reflectance
    for i_mu in range(RES):
        guess = np.array([1.0, 0.0])
        for i_alpha in reversed(range(RES)):
            r = reflectance[i_mu, i_alpha]
            if r < 3e-6:
                continue

            def loss(x, r=r, h=hist[i_mu, i_alpha]):
                return np.sum(np.abs(ltc(r, x[0], x[1]) - h) ** 3)

            res = minimize(loss, guess, method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-12, "maxiter": 20000})
            table[i_mu, i_alpha, :2] = res.x
            guess = res.x
    return table


def write_rust(table, paths, path):
    names = ["A", "B", "REFLECTANCE"]
    docs = [
        "Inverse-transform entry a (= m11 = m22).",
        "Inverse-transform entry b (= m13).",
        "Directional albedo R of the layer.",
    ]
    with open(path, "w") as f:
        f.write(
            "//! The microfibre sheen's table: the inverse LTC matrix entries and the\n"
            "//! albedo of Zeltner, Burley & Chiang's (2022) fibre layer, for roughness α\n"
            "//! (rows) and cos θo (columns), both `max(0.01, k/31)`. Written by\n"
            f"//! `tools/dev/fit_sheen_ltc.py --paths {paths}`; do not edit.\n\n"
            "/// Entries per axis.\n"
            f"pub const SIZE: usize = {RES};\n"
        )
        for k, (name, doc) in enumerate(zip(names, docs)):
            f.write(f"\n/// {doc}\n#[rustfmt::skip]\npub const {name}: [[f32; SIZE]; SIZE] = [\n")
            for i_alpha in range(RES):
                row = ", ".join(f"{table[i_mu, i_alpha, k]:.5}" for i_mu in range(RES))
                f.write(f"    [{row}],\n")
            f.write("];\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--paths", type=int, default=1 << 21, help="paths per entry")
    parser.add_argument("--out", default=str(pathlib.Path(__file__).parents[2] / "src/render/bsdf/sheen_table.rs"))
    args = parser.parse_args()
    paths = max(CHUNK, args.paths // CHUNK * CHUNK)
    jobs = [(i_mu, i_alpha, paths) for i_alpha in range(RES) for i_mu in range(RES)]
    reflectance = np.zeros((RES, RES))
    hist = np.zeros((RES, RES, RES, RES))
    with multiprocessing.Pool() as pool:
        for n, (i_mu, i_alpha, r, h) in enumerate(pool.imap_unordered(measure, jobs)):
            reflectance[i_mu, i_alpha] = r
            hist[i_mu, i_alpha] = h
            if n % 64 == 0:
                print(f"{n}/{len(jobs)} entries", flush=True)
    table = fit(reflectance, hist)
    np.save("/tmp/sheen_fit.npy", np.stack([reflectance, *np.moveaxis(table[:, :, :2], 2, 0)]))
    write_rust(table, paths, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
