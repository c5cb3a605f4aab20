"""Numba kernels of the spherical KDE: the sum of vMF kernels on an equal-area grid.

Nopython code only; the checks of the arguments, the chunking and the public entry
points are in :mod:`tiltlab.sphere._kde_grid` and :mod:`tiltlab.sphere.kde`, which
also describe the two quadratures.

Speed. Per kernel, the cosines of the longitude differences are computed once per
column of a window around its centre, so a cell costs one multiply-add; the mass
quadrature finds each row's cells by walking from the previous row's (no arccos per
row), evaluates exp with :func:`_exp_nonpos` (branch-free, within 2 ulp of exp, so
the loop vectorises, unlike libm's scalar exp) and sums the values in vectorised
order. The density therefore equals a plain evaluation of the same truncated kernel
sum to rounding (relative ~1e-15; ``tests/test_sphere_kde_fast.py`` checks 1e-13
against a brute-force sum over every cell); the point quadrature's arithmetic is
unchanged.
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba import njit, prange, types
from numba.extending import intrinsic


@njit(cache=True)
def _cell_tables(n_lon, n_lat):
    """Return cos/sin of the cell-centre longitudes and sin/cos of their latitudes."""
    dlon = 2.0 * np.pi / n_lon
    ds = 2.0 / n_lat
    clon = np.empty(n_lon)
    slon = np.empty(n_lon)
    for j in range(n_lon):
        a = -np.pi + (j + 0.5) * dlon
        clon[j] = np.cos(a)
        slon[j] = np.sin(a)
    sc = np.empty(n_lat)
    cc = np.empty(n_lat)
    for r in range(n_lat):
        sc[r] = -1.0 + (r + 0.5) * ds
        cc[r] = np.sqrt(1.0 - sc[r] * sc[r])
    return clon, slon, sc, cc


@njit(cache=True)
def _cos_to_cell(si, ci, cl, sl, sr, cr, cj, sj):
    """Return the cosine of the distance from a kernel centre to a cell centre.

    ``si``, ``ci``, ``cl``, ``sl``: sin and cos of the latitude, cos and sin of the
    longitude of the kernel centre; ``sr``, ``cr`` the sine and cosine of the cell's
    latitude, ``cj``, ``sj`` the cosine and sine of its longitude.
    """
    return si * sr + ci * cr * (cj * cl + sj * sl)


@njit(cache=True)
def _cut(pt, lon_i, k, log_tol, mass, tables, n_lon):
    """Return the truncation cosine of a kernel and the grid row holding its centre.

    Point quadrature: the cap where the kernel is above ``log_tol`` of its peak (row -1).
    Mass quadrature: the same cap measured from the nearest approach bound, the centre
    of the cell holding the kernel's centre.
    """
    clon, slon, sc, cc = tables
    n_lat = sc.shape[0]
    if mass:
        r_own = min(max(int((pt[0] + 1.0) / (2.0 / n_lat)), 0), n_lat - 1)
        j_own = min(max(int((lon_i + np.pi) / (2.0 * np.pi / n_lon)), 0), n_lon - 1)
        c_own = _cos_to_cell(
            pt[0], pt[1], pt[2], pt[3], sc[r_own], cc[r_own], clon[j_own], slon[j_own]
        )
        cos_cut = min(c_own, 1.0) - 1e-12
    else:
        r_own = -1
        cos_cut = 1.0
    if k > 0.0:
        cos_cut += log_tol / k
    else:  # flat kernel (h so large that 1/h² underflows)
        cos_cut = -2.0
    return cos_cut, r_own


@njit(cache=True)
def _row_columns(pt, lon_i, cos_cut, sr, cr, n_lon):
    """Return the first and last column of a row's cells inside the truncation cap."""
    den = pt[1] * cr
    if den < 1e-300:
        return (0, n_lon - 1) if pt[0] * sr >= cos_cut else (0, -1)
    cd = (cos_cut - pt[0] * sr) / den
    if cd <= -1.0:
        return 0, n_lon - 1
    if cd > 1.0:
        return 0, -1
    half = np.arccos(cd)
    dlon = 2.0 * np.pi / n_lon
    j0 = int(np.floor((lon_i - half + np.pi) / dlon - 0.5))
    j1 = int(np.ceil((lon_i + half + np.pi) / dlon - 0.5))
    if j1 - j0 + 1 >= n_lon:
        return 0, n_lon - 1
    return j0, j1


@njit(cache=True)
def _cap_rows(pt, cos_cut, r_own, n_lat):
    """Return the first and last grid row of the cap and its angular radius."""
    ds = 2.0 / n_lat
    if cos_cut <= -1.0:
        theta = np.pi
    else:
        theta = np.arccos(min(cos_cut, 1.0))
    psi = np.arcsin(pt[0])
    lo = psi - theta
    hi = psi + theta
    s_lo = -1.0 if lo <= -0.5 * np.pi else np.sin(lo)
    s_hi = 1.0 if hi >= 0.5 * np.pi else np.sin(hi)
    r0 = max(int((s_lo + 1.0) / ds), 0)
    r1 = min(int((s_hi + 1.0) / ds), n_lat - 1)
    if r_own >= 0:
        r0 = min(r0, r_own)
        r1 = max(r1, r_own)
    return r0, r1, theta


@njit(cache=True)
def _cap(pt, lon_i, cos_cut, r_own, tables, n_lon, jlo, jhi):
    """Fill ``jlo``, ``jhi`` with the columns of the cap's cells; return its rows."""
    sc = tables[2]
    cc = tables[3]
    r0, r1, _ = _cap_rows(pt, cos_cut, r_own, sc.shape[0])
    cos_cut = max(cos_cut, -1.0)
    for r in range(r0, r1 + 1):
        jlo[r], jhi[r] = _row_columns(pt, lon_i, cos_cut, sc[r], cc[r], n_lon)
    return r0, r1


@njit(cache=True)
def _point_norm(k, wi, exact):
    """Return the weighted normalising constant of a kernel (vMF or Gaussian-on-chord)."""
    if not exact:
        return wi * k / (2.0 * np.pi)
    if k < 1e-8:  # k / (1 - e^{-2k}) -> 1/2 + k/2
        return wi * (0.5 + 0.5 * k) / np.pi
    return wi * k / (2.0 * np.pi * (-np.expm1(-2.0 * k)))


# ---------------------------------------------------------------------------
# exp(x) for x <= 0, in a form LLVM vectorises (libm's exp is a scalar call)
# ---------------------------------------------------------------------------

# ln 2 = _LN2_HI + _LN2_LO: _LN2_HI keeps 21 significant bits, so t·_LN2_HI is exact
# for the |t| <= 1077 used here and x - t·_LN2_HI is exact (Sterbenz); _LN2_LO is the
# rest of ln 2 rounded to double.
_LN2_HI = 0.6931467056274414  # 0x1.62e42p-1
_LN2_LO = 4.7493250390316726e-07  # 0x1.fdf473de6af28p-22
_INV_LN2 = 1.4426950408889634


@intrinsic
def _as_float(typingctx, bits):
    """Reinterpret the bits of an int64 as a float64."""
    sig = types.float64(types.int64)

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())

    return sig, codegen


@njit(cache=True, fastmath={"contract"})
def _exp_nonpos(x):
    """Return exp(x) for x <= 0, within 2 ulp (0 below -746 and for NaN).

    x = t ln 2 + r with t = round(x / ln 2), |r| <= ln(2)/2; exp(r) by its Taylor
    polynomial of degree 13 (truncation error < |r|^14/14! < 5·10⁻¹⁸ relative), times
    2^t = 2^⌊t/2⌋ 2^(t-⌊t/2⌋) (two normal powers of two built from their bits, so that
    subnormal results are rounded once). Branch-free, so loops over it vectorise.
    """
    x = x if x > -746.0 else -746.0
    t = np.floor(x * _INV_LN2 + 0.5)
    r = (x - t * _LN2_HI) - t * _LN2_LO
    p = 1.0 / 6227020800.0
    p = p * r + 1.0 / 479001600.0
    p = p * r + 1.0 / 39916800.0
    p = p * r + 1.0 / 3628800.0
    p = p * r + 1.0 / 362880.0
    p = p * r + 1.0 / 40320.0
    p = p * r + 1.0 / 5040.0
    p = p * r + 1.0 / 720.0
    p = p * r + 1.0 / 120.0
    p = p * r + 1.0 / 24.0
    p = p * r + 1.0 / 6.0
    p = p * r + 0.5
    p = p * r + 1.0
    p = p * r + 1.0
    n = np.int64(t)
    n1 = n >> 1
    return p * _as_float((n1 + 1023) << 52) * _as_float((n - n1 + 1023) << 52)


# ---------------------------------------------------------------------------
# the kernel sum. Inner loops slice their arrays themselves (a view passed to a
# function costs reference counting) and run over plain ranges, so they vectorise.
# ---------------------------------------------------------------------------


@njit(cache=True)
def _column_cosines(pt, rows, jlo, jhi, clon, slon, cdl):
    """Store cos(Δlongitude) of the cap's columns in ``cdl``; return the first column.

    ``cdl[j - j_first]`` is the cosine of the longitude between the kernel centre and
    column ``j`` of the cap (j may lie outside [0, n_lon): it wraps), so that the
    cosine of the distance to cell (r, j) is ``sin ψ sin ψ_r + cos ψ cos ψ_r cdl[…]``,
    the arithmetic of :func:`_cos_to_cell`.
    """
    n_lon = clon.shape[0]
    j_first = 1 << 40
    j_last = -(1 << 40)
    for r in range(rows[0], rows[1] + 1):
        if jhi[r] >= jlo[r]:
            j_first = min(j_first, jlo[r])
            j_last = max(j_last, jhi[r])
    cl, sl = pt[2], pt[3]
    jj = j_first % n_lon  # Python semantics: in [0, n_lon)
    for t in range(j_last - j_first + 1):
        cdl[t] = clon[jj] * cl + slon[jj] * sl
        jj += 1
        if jj == n_lon:
            jj = 0
    return j_first


@njit(cache=True)
def _window(pt, lon_i, theta, tables, cdl):
    """Store cos(Δlongitude) of the columns that can hold the cap in ``cdl``.

    The window is centred on the column holding the kernel centre: the longitudes of a
    cap of radius θ around latitude ψ stay within asin(sin θ / cos ψ) of its centre
    (plus two columns of margin), or it is every column, starting half a turn away,
    when the cap holds a pole. Return the window's first column (which may lie outside
    [0, n_lon): columns wrap), its length and the index of its centre column; the
    cosines fall off monotonically on either side of that centre.
    """
    clon, slon = tables[0], tables[1]
    n_lon = clon.shape[0]
    dlon = 2.0 * np.pi / n_lon
    jc = min(max(int((lon_i + np.pi) / dlon), 0), n_lon - 1)
    full = theta >= 0.5 * np.pi or np.sin(theta) >= pt[1]
    half_w = 0
    if not full:
        half_w = int(np.arcsin(np.sin(theta) / pt[1]) / dlon) + 2
        full = 2 * half_w + 1 >= n_lon
    if full:
        tc = n_lon // 2
        length = n_lon
    else:
        tc = half_w
        length = 2 * half_w + 1
    start = jc - tc
    cl, sl = pt[2], pt[3]
    jj = start % n_lon  # Python semantics: in [0, n_lon)
    for t in range(length):
        cdl[t] = clon[jj] * cl + slon[jj] * sl
        jj += 1
        if jj == n_lon:
            jj = 0
    return start, length, tc


@njit(cache=True)
def _walk(a, b, cdl, cos_cut, t0, t1, length):
    """Move the ends t0 <= t1 of a row's range to the cells with a + b·cdl >= cos_cut."""
    if a + b * cdl[t0] >= cos_cut:
        while t0 > 0 and a + b * cdl[t0 - 1] >= cos_cut:
            t0 -= 1
    else:
        while a + b * cdl[t0] < cos_cut:
            t0 += 1
    if a + b * cdl[t1] >= cos_cut:
        while t1 < length - 1 and a + b * cdl[t1 + 1] >= cos_cut:
            t1 += 1
    else:
        while a + b * cdl[t1] < cos_cut:
            t1 -= 1
    return t0, t1


@njit(cache=True)
def _mass_cap(pt, lon_i, cos_cut, r_own, tables, jlo, jhi, cdl):
    """Fill ``jlo``, ``jhi`` with the cap's cells (cos(distance) >= ``cos_cut``), row by row.

    Like :func:`_cap`, without an arccos per row: each row's range is found by walking
    from the previous row's along the window's column cosines (:func:`_window`); a row
    whose centre column is outside the cap is empty. Return the rows, the window's
    first column and the largest cos(distance) of the cap's cells, which lies at the
    centre column (or next to it, in a tie) in some row.
    """
    sc, cc = tables[2], tables[3]
    r0, r1, theta = _cap_rows(pt, cos_cut, r_own, sc.shape[0])
    start, length, tc = _window(pt, lon_i, theta, tables, cdl)
    si, ci = pt[0], pt[1]
    t0 = t1 = tc
    cmax = -2.0
    for r in range(r0, r1 + 1):
        a = si * sc[r]
        b = ci * cc[r]
        if a + b * cdl[tc] < cos_cut:
            jlo[r], jhi[r] = 0, -1
            t0 = t1 = tc
            continue
        t0, t1 = _walk(a, b, cdl, cos_cut, t0, t1, length)
        jlo[r], jhi[r] = start + t0, start + t1
        for t in range(max(t0, tc - 1), min(t1, tc + 1) + 1):
            cmax = max(cmax, a + b * cdl[t])
    return (r0, r1), start, cmax


@njit(cache=True)
def _row_values(buf, q, cdl, c0, n, ab, cmax, k, log_tol):
    """Store the kernel values of a row's cells, relative to the largest, in ``buf``.

    ``ab`` = (a, b): the cosine of the distance to the cells is ``a + b * cdl[c0:c0 +
    n]``; values below ``log_tol`` (log, relative to ``cmax``'s) are 0. Branch-free
    (see :func:`_exp_nonpos`), so the loop vectorises.
    """
    out = buf[q : q + n]
    c = cdl[c0 : c0 + n]
    a, b = ab
    for j in range(n):
        d = (a + b * c[j]) - cmax
        x = k * d if d < 0.0 else 0.0
        e = _exp_nonpos(x)
        out[j] = e if x >= log_tol else 0.0


@njit(cache=True)
def _cap_values(pt, rows, jlo, jhi, tables, cdl, start, kernel, buf):
    """Store the kernel values of the cap's cells in ``buf``, row by row; return their count.

    ``kernel`` is (largest cos(distance), κ, log of the truncation).
    """
    sc, cc = tables[2], tables[3]
    si, ci = pt[0], pt[1]
    cmax, k, log_tol = kernel
    q = 0
    for r in range(rows[0], rows[1] + 1):
        n = jhi[r] - jlo[r] + 1
        if n <= 0:
            continue
        ab = (si * sc[r], ci * cc[r])
        _row_values(buf, q, cdl, jlo[r] - start, n, ab, cmax, k, log_tol)
        q += n
    return q


@njit(cache=True, fastmath={"reassoc"})
def _sum(buf, q):
    """Return the sum of ``buf[:q]`` (in any order, so that it vectorises)."""
    v = buf[:q]
    tot = 0.0
    for p in range(q):
        tot += v[p]
    return tot


@njit(cache=True)
def _add_scaled(acc, a0, f, buf, q, n):
    """Add ``f * buf[q:q + n]`` to ``acc[a0:a0 + n]``."""
    out = acc[a0 : a0 + n]
    v = buf[q : q + n]
    for j in range(n):
        out[j] += f * v[j]


@njit(cache=True)
def _deposit(acc, n_lon, rows, jlo, jhi, f, buf):
    """Add ``f`` times the values of ``buf`` to the cap's cells (row by row, wrapping).

    ``acc`` is the flat (n_lat·n_lon) accumulator.
    """
    q = 0
    for r in range(rows[0], rows[1] + 1):
        n = jhi[r] - jlo[r] + 1
        if n <= 0:
            continue
        j0 = jlo[r] % n_lon
        m = min(n, n_lon - j0)
        _add_scaled(acc, r * n_lon + j0, f, buf, q, m)
        if m < n:
            _add_scaled(acc, r * n_lon, f, buf, q + m, n - m)
        q += n


@njit(cache=True)
def _add_point(acc, pt, rows, jlo, jhi, tables, k, norm, cdl):
    """Add a kernel evaluated at the cell centres of its cap (flat accumulator)."""
    clon, slon, sc, cc = tables
    n_lon = clon.shape[0]
    si, ci = pt[0], pt[1]
    j_first = _column_cosines(pt, rows, jlo, jhi, clon, slon, cdl)
    for r in range(rows[0], rows[1] + 1):
        a = si * sc[r]
        b = ci * cc[r]
        for j in range(jlo[r], jhi[r] + 1):
            cosd = a + b * cdl[j - j_first]
            acc[r * n_lon + j % n_lon] += norm * np.exp(k * (cosd - 1.0))


@njit(cache=True)
def _add_mass(acc, pt, lon_i, cut, jlo, jhi, tables, k, m, area, log_tol, work):
    """Add a kernel that puts exactly the mass ``m`` on the grid (cells of ``area``).

    ``cut`` is (truncation cosine, row of the centre) from :func:`_cut`. Pass 1: the
    cap's cells and the largest cos(distance); pass 2: their values relative to the
    largest, truncated at ``log_tol`` below it; pass 3: deposit, divided by their sum.
    """
    cdl, buf = work
    rows, start, cmax = _mass_cap(pt, lon_i, cut[0], cut[1], tables, jlo, jhi, cdl)
    q = _cap_values(pt, rows, jlo, jhi, tables, cdl, start, (cmax, k, log_tol), buf)
    tot = _sum(buf, q)
    _deposit(acc, tables[0].shape[0], rows, jlo, jhi, m / (tot * area), buf)


@njit(cache=True, parallel=True)
def _kde_scatter(lon, s, kap, w, n_lon, n_lat, log_tol, exact, mass, out, scratch):
    """Add every kernel to ``out`` (one flat n_lat·n_lon accumulator per chunk).

    ``mass=False``: kernel values at the cell centres (point evaluation, truncated at
    ``log_tol`` below the peak). ``mass=True``: the same values, relative to the
    largest one on the grid and truncated at ``log_tol`` below it, divided by their sum
    so that every kernel puts exactly its mass (times the cell area) on the grid;
    ``scratch`` (one row of n_lat·n_lon per chunk) holds them between the passes.
    """
    nchunk = out.shape[0]
    npts = lon.shape[0]
    area = (2.0 * np.pi / n_lon) * (2.0 / n_lat)
    tables = _cell_tables(n_lon, n_lat)
    for ch in prange(nchunk):
        acc = out[ch]
        work = (np.empty(3 * n_lon + 2), scratch[ch])
        jlo = np.empty(n_lat, np.int64)
        jhi = np.empty(n_lat, np.int64)
        pt = np.empty(4)
        for i in range(ch * npts // nchunk, (ch + 1) * npts // nchunk):
            k = kap[i]
            wi = w[i]
            if wi == 0.0:
                continue
            pt[0] = s[i]
            pt[1] = np.sqrt(max(1.0 - s[i] * s[i], 0.0))
            pt[2] = np.cos(lon[i])
            pt[3] = np.sin(lon[i])
            cut = _cut(pt, lon[i], k, log_tol, mass, tables, n_lon)
            if mass:
                # the kernel's exact mass: 1 (vMF) or 1 - e^{-2k} (Gaussian-on-chord)
                m = wi if exact else wi * (-np.expm1(-2.0 * k))
                _add_mass(
                    acc, pt, lon[i], cut, jlo, jhi, tables, k, m, area, log_tol, work
                )
            else:
                rows = _cap(pt, lon[i], cut[0], cut[1], tables, n_lon, jlo, jhi)
                norm = _point_norm(k, wi, exact)
                _add_point(acc, pt, rows, jlo, jhi, tables, k, norm, work[0])
