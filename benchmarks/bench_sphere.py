"""Speed of tiltlab.sphere: facet binning, spherical KDE, residence maps, with reference
timings from the same run.

Targets: binning 1 M unit vectors into the 5000-vertex triangulation < 1 s
(triangulation included, cached; issue 6); KDE of 1 M samples on a ~1° equal-area grid
< 2 s with the default bandwidth and grid ("Fast again", item 3). Scaling lines give the
time at n/100, n/10 and n with the fitted exponent of time ~ n^b: binning is linear,
the KDE grows ~ n^(2/3) (the reference bandwidth shrinks as n^(-1/6), so every kernel
covers ~ n^(-1/3) cells).
The sphere functions take labelled tilt (a (time, axis) DataArray such as
``filters.gravity``'s, with ``fs`` and a time coordinate) as well as plain arrays; the
labelled path adds the validation of ``tiltlab._validate.signal``, timed here too.

Run: python benchmarks/bench_sphere.py [N_BIN] [N_KDE]
"""

import sys
import time

import numpy as np
import xarray as xr
from scipy.spatial import cKDTree

from tiltlab import sphere as S
from _timing import best_of, print_scaling, scaling


def labelled(g: np.ndarray, fs: float) -> xr.DataArray:
    """A tilt series shaped like ``filters.gravity``'s output."""
    return xr.DataArray(
        g,
        dims=("time", "axis"),
        name="gravity",
        coords={"time": np.arange(len(g)) / fs, "axis": list("xyz")},
        attrs={"fs": fs, "units": "1"},
    )


def main(n_bin: int = 1_000_000, n_kde: int = 1_000_000) -> None:
    rng = np.random.default_rng(0)
    x = rng.normal(size=(n_bin, 3))
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    # load/compile the numba kernels
    S.locate(x[:10], S.triangulate(S.fibonacci_lattice(100)))

    S.sphere_mesh.cache_clear()
    t0 = time.perf_counter()
    mesh = S.sphere_mesh(5000)
    t_build = time.perf_counter() - t0
    t_cached = best_of(lambda: S.sphere_mesh(5000))
    t_bin = best_of(lambda: S.histogram(x, mesh))
    xl = labelled(x, 100.0)
    t_bin_l = best_of(lambda: S.histogram(xl, mesh))
    t_map_l = best_of(lambda: S.tilt_map(xl, mesh=mesh))
    tree = cKDTree(mesh.vertices)
    t_tree = best_of(lambda: tree.query(x, workers=-1))
    print(
        f"triangulation (5000 vertices, {mesh.n_faces} facets): "
        f"build {t_build * 1e3:.1f} ms, cached {t_cached * 1e6:.1f} µs"
    )
    print(
        f"binning {n_bin:,} vectors: {t_bin:.3f} s  ({n_bin / t_bin / 1e6:.1f} M/s); "
        f"with a fresh triangulation {t_bin + t_build:.3f} s   [target < 1 s]"
    )
    print(
        f"  labelled input (DataArray with fs and time): histogram {t_bin_l:.3f} s, "
        f"tilt_map {t_map_l:.3f} s"
    )
    print(
        f"  reference: scipy cKDTree nearest-vertex query alone {t_tree:.3f} s "
        f"-> ratio {t_tree / t_bin:.1f}x"
    )

    sizes = [n_bin // 100, n_bin // 10, n_bin]
    times, b = scaling(lambda n: S.histogram(x[:n], mesh), sizes)
    print_scaling("binning (cached)", sizes, times, b)

    g = S.vmf_sample([0.3, 0.2, 1.0], 10.0, n_kde, rng)
    S.kde(g[:100], h=0.1)  # load/compile
    t_full = best_of(lambda: S.kde(g))
    res = S.kde(g)
    grid, h = res.grid, res.h
    t_kde = best_of(lambda: S.kde(g, grid=grid, h=h))
    print(
        f"KDE {n_kde:,} samples (vMF κ = 10) on a {grid.n_lat}x{grid.n_lon} "
        f"equal-area grid (~1°), default bandwidth h = {h:.4f} rad and grid: "
        f"{t_full:.3f} s (integral {res.integral():.12f})   [target < 2 s]"
    )
    print(f"  with the grid and h given: {t_kde:.3f} s")
    sizes = [n_kde // 100, n_kde // 10, n_kde]
    times, b = scaling(lambda n: S.kde(g[:n]), sizes)
    print_scaling("KDE (default h)", sizes, times, b)
    sub = 2000
    c = grid.centres().reshape(-1, 3)
    t_dense = best_of(lambda: np.exp((c @ g[:sub].T - 1) / h**2).sum(1), repeat=1)
    t_dense *= n_kde / sub
    print(
        "  reference: dense numpy kernel sum (no truncation), extrapolated from "
        f"{sub} samples: {t_dense:.1f} s -> ratio {t_dense / t_kde:.0f}x"
    )
    # correlated series; its sampling rate travels with it
    n_walk = min(n_kde, 100_000)
    traj = np.cumsum(rng.normal(size=(n_walk, 3)) * 0.01, axis=0) + [0, 0, 3]
    traj = labelled(traj / np.linalg.norm(traj, axis=1, keepdims=True), 100.0)
    t_mkde = best_of(lambda: S.mkde(traj, grid=grid, h=h), repeat=1)
    print(
        f"MKDE of a {n_walk:,}-sample random walk (steps ~0.01 rad, fs from attrs): "
        f"{t_mkde:.3f} s"
    )

    walk = np.cumsum(rng.normal(size=(20_000, 3)) * 0.02, axis=0) + [0, 0, 2]
    walk = labelled(walk / np.linalg.norm(walk, axis=1, keepdims=True), 100.0)
    centres = S.fibonacci_lattice(2000)
    S.residence(walk[:10], centres[:2], 0.1, 1.0)
    t_res = best_of(lambda: S.residence(walk, centres, 0.1, 1.0), repeat=1)
    print(
        f"residence/visits map: 20,000 samples x 2000 centres: {t_res:.3f} s "
        f"({20_000 * 2000 / t_res / 1e6:.0f} M sample-centre pairs/s)"
    )


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:]]
    main(*args)
