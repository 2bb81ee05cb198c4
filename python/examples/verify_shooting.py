"""Validating a user's shooting table with ``verify`` (README, "Verifying
shooting results"): each row (clamps, n(0), m(0), and what its author
claims) is checked by the continuum equations integrated adaptively and
polished, and by the discrete rod at N, 2N, 4N.

    python python/examples/verify_shooting.py [TABLE] [N]
"""

import pathlib
import sys

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(table: str = str(ROOT / "scenes/verify/two_equilibria.toml"), n: int = 50) -> list:
    checks = knotrod.verify(table, segments=(n, 2 * n, 4 * n))
    for c in checks:
        name = c["given"]["name"]
        print(f"{name}: {c['verdict']}")
        for claim in c.get("claims", []):
            # Confirmed, Refuted, or Undecided (the error bar straddles it)
            mark = {"Confirmed": "confirmed", "Refuted": "REFUTED"}.get(claim["outcome"], "undecided")
            print(f"   claims {claim['claim']} = {claim['claimed']}: found {claim['found']} ({mark})")
    return checks


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "scenes/verify/two_equilibria.toml"), int(sys.argv[2]) if len(sys.argv) > 2 else 50)
