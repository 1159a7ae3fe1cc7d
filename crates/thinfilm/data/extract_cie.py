#!/usr/bin/env python3
"""Extract CIE tables from a colour-science wheel's source into compact CSV files.

Usage: pip download --no-deps colour-science -d /tmp/cs && unzip the wheel, then
    python3 extract_cie.py /path/to/unzipped/colour  crates/thinfilm/data

Reads the dataset modules as text (nothing is imported or executed) and writes
one CSV per table. See README.md in this directory for the provenance.
"""

import pathlib
import re
import sys


def table(source: str, key: str) -> list[tuple[float, list[float]]]:
    """Rows `wavelength: value` or `wavelength: (x, y, z)` of the dict entry `key`."""
    start = source.index(f'"{key}": {{')
    end = source.index("}", start)
    rows = []
    for line in source[start:end].splitlines()[1:]:
        m = re.match(r"\s*([0-9.]+):\s*\(?([^)]*?)\)?,?\s*$", line)
        if m:
            values = [v.strip() for v in m.group(2).split(",") if v.strip()]
            rows.append((m.group(1), values))
    return rows


def write(path: pathlib.Path, header: str, rows) -> None:
    lines = [header] + [",".join([w] + v) for w, v in rows]
    path.write_text("\n".join(lines) + "\n")
    print(f"{path}: {len(rows)} rows")


def main() -> None:
    colour, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
    datasets = colour / "colorimetry" / "datasets"
    cmfs = (datasets / "cmfs.py").read_text()
    sds = (datasets / "illuminants" / "sds.py").read_text()
    write(out / "cie1931_2deg_cmf.csv", "wavelength_nm,x_bar,y_bar,z_bar",
          table(cmfs, "CIE 1931 2 Degree Standard Observer"))
    write(out / "cie1964_10deg_cmf.csv", "wavelength_nm,x_bar,y_bar,z_bar",
          table(cmfs, "CIE 1964 10 Degree Standard Observer"))
    for key, name in [("D65", "d65"), ("D50", "d50"), ("FL2", "f2"), ("FL11", "f11"), ("A", "a")]:
        write(out / f"illuminant_{name}.csv", "wavelength_nm,value", table(sds, key))


if __name__ == "__main__":
    main()
