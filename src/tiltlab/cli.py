"""``tiltlab`` command line: inspect, validate and fetch data.

Examples
--------
::

    tiltlab fetch --all                # download (or verify in the mirror) every registered file
    tiltlab info broad:2               # summary of BROAD trial 2
    tiltlab validate session.nc        # check a saved Recording against the contract
"""

from __future__ import annotations

import argparse
import sys

__all__ = ["main"]


def _load(spec: str):
    from . import datasets

    return datasets.load(spec)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="tiltlab", description=__doc__.splitlines()[0]
    )
    sub = parser.add_subparsers(dest="cmd", required=True)
    p_fetch = sub.add_parser(
        "fetch", help="fetch registered data files (checksums verified)"
    )
    p_fetch.add_argument(
        "names",
        nargs="*",
        help="registry names, e.g. broad/02_undisturbed_slow_rotation_B.hdf5",
    )
    p_fetch.add_argument("--all", action="store_true", help="every registered file")
    p_info = sub.add_parser("info", help="summarise a recording")
    p_info.add_argument("source")
    p_val = sub.add_parser("validate", help="validate a recording against the contract")
    p_val.add_argument("source")
    args = parser.parse_args(argv)

    from . import datasets, schema

    try:
        if args.cmd == "fetch":
            names = list(datasets.registry()) if args.all else args.names
            if not names:
                parser.error("give file names or --all")
            from tqdm import tqdm

            for name in tqdm(names, desc="fetching", unit="file"):
                datasets.fetch(name)
            print(f"{len(names)} file(s) present and verified")
        elif args.cmd == "info":
            rec = _load(args.source)
            for k, v in schema.describe(rec).items():
                print(f"{k:>14}: {v}")
        elif args.cmd == "validate":
            rec = _load(args.source)
            schema.validate(rec, allow_nan=True)
            print(f"{args.source}: valid Recording")
    except (datasets.DataError, schema.RecordingError, OSError) as exc:
        print(f"tiltlab: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
