"""Numba kernels of the spherical KDE: the sum of vMF kernels on an equal-area grid.

Nopython code only; the checks of the arguments, the chunking and the public entry
points are in :mod:`tiltlab.sphere._kde_grid` and :mod:`tiltlab.sphere.kde`, which
also describe the two quadratures.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


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
def _cap(pt, lon_i, cos_cut, r_own, tables, n_lon, jlo, jhi):
    """Fill ``jlo``, ``jhi`` with the columns of the cap's cells; return its rows."""
    sc = tables[2]
    cc = tables[3]
    n_lat = sc.shape[0]
    ds = 2.0 / n_lat
    if cos_cut <= -1.0:
        theta = np.pi
        cos_cut = -1.0
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


@njit(cache=True)
def _row_cosines(pt, r, j0, j1, tables, buf, q):
    """Store from ``buf[q]`` the cos(distance) of the cells j0..j1 of row r; return the next q."""
    clon, slon, sc, cc = tables
    n_lon = clon.shape[0]
    si, ci, cl, sl = pt[0], pt[1], pt[2], pt[3]
    sr, cr = sc[r], cc[r]
    for j in range(j0, j1 + 1):
        jj = j % n_lon  # Python semantics: in [0, n_lon)
        buf[q] = _cos_to_cell(si, ci, cl, sl, sr, cr, clon[jj], slon[jj])
        q += 1
    return q


@njit(cache=True)
def _row_deposit(acc_row, j0, j1, f, buf, q):
    """Add ``f`` times ``buf[q:]`` to the cells j0..j1 of a row; return the next q."""
    n_lon = acc_row.shape[0]
    for j in range(j0, j1 + 1):
        acc_row[j % n_lon] += f * buf[q]
        q += 1
    return q


@njit(cache=True)
def _mass_values(buf, q, k, log_tol):
    """Turn ``buf[:q]`` into kernel values relative to the largest; return their sum."""
    cmax = -2.0
    for p in range(q):
        if buf[p] > cmax:
            cmax = buf[p]
    tot = 0.0
    for p in range(q):
        d = buf[p] - cmax
        if d >= 0.0:
            e = 1.0
        else:
            x = k * d
            e = np.exp(x) if x >= log_tol else 0.0
        buf[p] = e
        tot += e
    return tot


@njit(cache=True)
def _add_point(acc, pt, rows, jlo, jhi, tables, k, norm):
    """Add a kernel evaluated at the cell centres of its cap."""
    clon, slon, sc, cc = tables
    n_lon = clon.shape[0]
    si, ci, cl, sl = pt[0], pt[1], pt[2], pt[3]
    for r in range(rows[0], rows[1] + 1):
        sr, cr = sc[r], cc[r]
        for j in range(jlo[r], jhi[r] + 1):
            jj = j % n_lon
            cosd = _cos_to_cell(si, ci, cl, sl, sr, cr, clon[jj], slon[jj])
            acc[r, jj] += norm * np.exp(k * (cosd - 1.0))


@njit(cache=True, parallel=True)
def _kde_scatter(lon, s, kap, w, n_lon, n_lat, log_tol, exact, mass, out, scratch):
    """Add every kernel to ``out`` (one (n_lat, n_lon) accumulator per chunk).

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
        buf = scratch[ch]
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
            cos_cut, r_own = _cut(pt, lon[i], k, log_tol, mass, tables, n_lon)
            rows = _cap(pt, lon[i], cos_cut, r_own, tables, n_lon, jlo, jhi)
            if not mass:
                _add_point(
                    acc, pt, rows, jlo, jhi, tables, k, _point_norm(k, wi, exact)
                )
                continue
            # mass-conserving: pass 1, cos(distance) of every candidate cell
            q = 0
            for r in range(rows[0], rows[1] + 1):
                q = _row_cosines(pt, r, jlo[r], jhi[r], tables, buf, q)
            # pass 2: values relative to the largest, truncated at log_tol below it
            if q == 0:  # pragma: no cover - the own cell is always a candidate
                continue
            tot = _mass_values(buf, q, k, log_tol)
            # the kernel's exact mass: 1 (vMF) or 1 - e^{-2k} (Gaussian-on-chord, Eq. 15)
            m = wi if exact else wi * (-np.expm1(-2.0 * k))
            f = m / (tot * area)
            # pass 3: deposit in the same order
            q = 0
            for r in range(rows[0], rows[1] + 1):
                q = _row_deposit(acc[r], jlo[r], jhi[r], f, buf, q)
