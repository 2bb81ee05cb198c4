#!/usr/bin/env python3
"""Generate src/geometry/knot/table.rs: Alexander polynomials from KnotInfo.

Reads the KnotInfo knot table shipped by the PyPI package `database_knotinfo`
(the data SageMath's `KnotInfo` uses: a '|'-separated CSV inside the package,
read with `database_knotinfo.link_list()`; row 0 holds the column titles).

Included: the unknot 0_1, every prime knot with at most 10 crossings
(3_1 ... 10_165), and the torus knots T(2, 2k+1) with at most 11 crossings
that are not already in (only T(2,11) = KnotInfo 11a_367).

Normalisation: integer coefficients, lowest degree first, powers of t divided
out, sign chosen so that Delta(1) = +1.

Run from anywhere (the output path is relative to this file):
    python3 tools/knot_table/make_table.py
"""

import importlib.metadata
import re
import sys
from collections import defaultdict
from pathlib import Path

import database_knotinfo

REPO = Path(__file__).resolve().parents[2]
OUT = REPO / "src" / "geometry" / "knot" / "table.rs"
MAX_PRIME_CROSSINGS = 10
MAX_TORUS_CROSSINGS = 11

# --------------------------------------------------------------------------
# Integer polynomials: lists of ints, index = degree.


def trim(p):
    p = list(p)
    while len(p) > 1 and p[-1] == 0:
        p.pop()
    return p


def pmul(a, b):
    out = [0] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] += x * y
    return trim(out)


def pdiv_exact(a, b):
    """Quotient a / b over Z; asserts the division is exact."""
    a, b = trim(a), trim(b)
    assert b != [0]
    rem = list(a)
    q = [0] * max(1, len(a) - len(b) + 1)
    for i in range(len(a) - len(b), -1, -1):
        c, r = divmod(rem[i + len(b) - 1], b[-1])
        assert r == 0, "non-integer quotient"
        q[i] = c
        for j, y in enumerate(b):
            rem[i + j] -= c * y
    assert all(x == 0 for x in rem), f"division not exact: {a} / {b}"
    return trim(q)


def t_pow_minus_one(n):
    """t^n - 1."""
    return [-1] + [0] * (n - 1) + [1]


def torus_alexander(p, q):
    """Delta of T(p,q) = (t^pq - 1)(t - 1) / ((t^p - 1)(t^q - 1))."""
    num = pmul(t_pow_minus_one(p * q), t_pow_minus_one(1))
    den = pmul(t_pow_minus_one(p), t_pow_minus_one(q))
    return normalise_dense(pdiv_exact(num, den))


# --------------------------------------------------------------------------
# Parsing and normalisation.

TERM = re.compile(
    r"""\s*([+-])?\s*          # sign
        (\d+)?\s*\*?\s*        # coefficient
        (t(?:\s*\^\s*(?:\(\s*(-?\d+)\s*\)|\{\s*(-?\d+)\s*\}|(-?\d+)))?)?  # t^e
        \s*""",
    re.VERBOSE,
)


def parse_poly(s):
    """Parse a Laurent polynomial in t, e.g. '1-3*t+ t^2' or 't^(-1)-1+t'.

    Returns {exponent: coefficient}.
    """
    s = s.strip()
    assert s, "empty polynomial"
    terms = defaultdict(int)
    pos = 0
    while pos < len(s):
        m = TERM.match(s, pos)
        if not m or m.end() == pos or (m.group(2) is None and m.group(3) is None):
            raise ValueError(f"cannot parse {s!r} at {pos}")
        if pos > 0 and m.group(1) is None:
            raise ValueError(f"missing operator in {s!r} at {pos}")
        sign = -1 if m.group(1) == "-" else 1
        coeff = int(m.group(2)) if m.group(2) is not None else 1
        if m.group(3) is None:
            exp = 0
        else:
            e = m.group(4) or m.group(5) or m.group(6)
            exp = int(e) if e is not None else 1
        terms[exp] += sign * coeff
        pos = m.end()
    return {e: c for e, c in terms.items() if c != 0}


def normalise_sparse(terms):
    assert terms, "zero polynomial"
    lo, hi = min(terms), max(terms)
    return normalise_dense([terms.get(e, 0) for e in range(lo, hi + 1)])


def normalise_dense(p):
    p = list(p)
    while p and p[0] == 0:
        p.pop(0)
    while p and p[-1] == 0:
        p.pop()
    assert p, "zero polynomial"
    s = sum(p)
    assert s in (1, -1), f"Delta(1) = {s}, not a knot's Alexander polynomial"
    return [c * s for c in p]


def from_vector(v):
    """KnotInfo 'Alexander (vector)': [min degree, max degree, coefficients...]."""
    nums = [int(x) for x in re.findall(r"-?\d+", v)]
    if len(nums) == 1:  # the unknot is stored as '1'
        return normalise_dense(nums)
    lo, hi, coeffs = nums[0], nums[1], nums[2:]
    assert len(coeffs) == hi - lo + 1, f"bad vector {v!r}"
    return normalise_dense(coeffs)


NAME = re.compile(r"^(\d+)([an]?)_(\d+)$")


def name_key(name):
    m = NAME.match(name)
    assert m, name
    return (int(m.group(1)), m.group(2), int(m.group(3)))


TORUS = re.compile(r"torus knot T\((\d+),(\d+)\)")

# --------------------------------------------------------------------------


def main():
    version = importlib.metadata.version("database_knotinfo")
    assert database_knotinfo.version() == version, (database_knotinfo.version(), version)
    rows = database_knotinfo.link_list()[1:]  # row 0: column titles

    knots = {}  # name -> (poly, crossings)
    torus = {}  # name -> (p, q)
    for r in rows:
        name = r["name"].strip()
        cr = int(r["crossing_number"])
        poly = normalise_sparse(parse_poly(r["alexander_polynomial"]))
        vec = r["alexander_polynomial_vector"].strip()
        if vec:
            assert from_vector(vec) == poly, (name, poly, vec)
        m = TORUS.search(r["geometric_type"])
        if m:
            torus[name] = (int(m.group(1)), int(m.group(2)))
        classical = NAME.match(name) and NAME.match(name).group(2) == ""
        if name == "0_1" or (classical and cr <= MAX_PRIME_CROSSINGS):
            assert name_key(name)[0] == cr, (name, cr)
            knots[name] = (poly, cr)
        elif m and int(m.group(1)) == 2 and cr <= MAX_TORUS_CROSSINGS:
            knots[name] = (poly, cr)  # T(2, 2k+1) beyond the prime range

    # ---- checks ----
    primes = [n for n, (_, c) in knots.items() if 0 < c <= MAX_PRIME_CROSSINGS]
    assert len(primes) == 249, len(primes)
    assert knots["0_1"] == ([1], 0)
    for n, (p, _) in knots.items():
        assert sum(p) == 1, n
        assert p == p[::-1], f"{n} not palindromic: {p}"
        assert len(p) % 2 == 1, n
        assert p[0] != 0 and p[-1] != 0, n

    spot = {
        "3_1": [1, -1, 1],
        "4_1": [-1, 3, -1],
        "5_1": [1, -1, 1, -1, 1],
        "5_2": [2, -3, 2],
        "6_1": [-2, 5, -2],
        "6_2": [-1, 3, -3, 3, -1],
        "6_3": [1, -3, 5, -3, 1],
        "8_19": [1, -1, 0, 1, 0, -1, 1],  # T(3,4), degree 6 = 2 * genus 3
        "8_20": [1, -2, 3, -2, 1],
        "10_124": [1, -1, 0, 1, -1, 1, 0, -1, 1],  # T(3,5)
    }
    for n, p in spot.items():
        assert knots[n][0] == p, (n, knots[n][0], p)
    assert knots["8_19"][0] == torus_alexander(3, 4)
    assert knots["10_124"][0] == torus_alexander(3, 5)
    assert torus["8_19"] == (3, 4) and torus["10_124"] == (3, 5)

    # Every torus knot in range: geometric type and polynomial agree.
    want_t2 = {(2, n) for n in range(3, MAX_TORUS_CROSSINGS + 1, 2)}
    have_t2 = set()
    for n, (p, q) in torus.items():
        if n in knots:
            assert knots[n][0] == torus_alexander(p, q), n
            assert knots[n][1] == min(p * (q - 1), q * (p - 1)), n
            if p == 2:
                have_t2.add((p, q))
    assert have_t2 == want_t2, (have_t2, want_t2)
    assert torus.get("11a_367") == (2, 11) and "11a_367" in knots

    # ---- output ----
    order = sorted(knots, key=lambda n: (knots[n][1], name_key(n)))
    lines = [
        "//! Alexander polynomials of the prime knots up to 10 crossings and the torus",
        f"//! knots T(2, 2k+1) up to 11 crossings, from KnotInfo (database_knotinfo {version}),",
        "//! generated by tools/knot_table/make_table.py — do not edit by hand.",
        "//! Normalised: lowest degree first, no factor t, Δ(1) = +1.",
        "",
        "/// (name, Alexander polynomial, crossing number), ordered by crossing number then name index.",
        "pub(super) const KNOTS: &[(&str, &[i64], u32)] = &[",
    ]
    for n in order:
        p, c = knots[n]
        if n in torus and torus[n][0] == 2 and c > MAX_PRIME_CROSSINGS:
            lines.append(f"    // T({torus[n][0]},{torus[n][1]}), KnotInfo name {n}.")
        coeffs = ", ".join(str(x) for x in p)
        lines.append(f'    ("{n}", &[{coeffs}], {c}),')
    lines.append("];")
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text("\n".join(lines) + "\n", encoding="utf-8")

    # ---- summary ----
    groups = defaultdict(list)
    for n in order:
        groups[tuple(knots[n][0])].append(n)
    shared = [
        g for g in (groups[k] for k in groups)
        if len([n for n in g if 0 < knots[n][1] <= MAX_PRIME_CROSSINGS]) > 1
    ]
    print(f"database_knotinfo {version}; wrote {OUT.relative_to(REPO)}")
    print(f"{len(knots)} knots ({len(primes)} prime knots with 3..10 crossings, "
          f"0_1, {len(knots) - len(primes) - 1} more torus knots T(2,q))")
    print(f"{len(groups)} distinct polynomials")
    print(f"{len(shared)} groups of prime knots <= 10 crossings sharing a polynomial:")
    for g in shared:
        print("  " + ", ".join(g) + "  " + str(list(knots[g[0]][0])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
