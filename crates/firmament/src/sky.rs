//! Evaluation of the precomputed tables (Bruneton & Neyret 2008 §5, eq. 16 pieces, as in
//! Bruneton 2017 `GetSkyRadiance`, `GetSkyRadianceToPoint`, `GetSunAndSkyIrradiance`).
//! Positions are planet-centred, in metres; directions are unit vectors.

use std::f64::consts::PI;

use crate::atmosphere::{LimbDarkening, Model};
use crate::geometry::{dot, length, ray_intersects_ground, safe_sqrt, Vec3};
use crate::lut::context::smoothstep;
use crate::lut::precompute::Groups;
use crate::lut::{Lookup, MieStorage, Tables};
use crate::Result;

/// A model with its tables, ready to evaluate.
pub struct Sky {
    /// The resolved atmosphere.
    pub model: Model,
    /// Its tables.
    pub tables: Tables,
    groups: Groups,
}

impl Sky {
    /// Pair a model with tables computed for it (refused if they do not match).
    pub fn new(model: Model, tables: Tables) -> Result<Sky> {
        tables.check_matches(&model, "(in memory)")?;
        let groups = Groups::new(&model);
        Ok(Sky {
            model,
            tables,
            groups,
        })
    }

    /// Number of wavelengths.
    pub fn channels(&self) -> usize {
        self.model.channels()
    }

    /// Table lookups.
    pub fn lookup(&self) -> Lookup<'_> {
        Lookup::new(
            &self.model,
            self.tables.config.sizes,
            &self.tables.optical_depth,
        )
    }

    /// Molecular phase function value.
    #[inline]
    pub fn rayleigh_phase(&self, nu: f64) -> f64 {
        self.groups.phase[0].eval(nu)
    }

    /// Aerosol phase function value.
    #[inline]
    pub fn mie_phase(&self, nu: f64) -> f64 {
        self.groups.phase[1].eval(nu)
    }

    /// Rayleigh+multiple (divided by the molecular phase function) and single Mie scattering
    /// at (r, μ, μ_s, ν), without phase functions
    /// (Bruneton 2017 `GetCombinedScattering`; the ratio rule for red-only Mie).
    /// The tables filtered for a fixed observer radius and sun zenith cosine: every view
    /// ray of a frame from a camera inside the atmosphere shares (r, μ_s), so the 4D lookup
    /// becomes a 2D one (same values).
    pub fn slice(&self, r: f64, mu_s: f64) -> SkySlice {
        let lk = self.lookup();
        let uvwz =
            crate::lut::params::scattering_uvwz(&lk.radii, &lk.sizes, r, 0.0, mu_s, 0.0, false);
        let n = self.channels();
        let single = self.tables.scattering.slice(uvwz[1], uvwz[3]);
        let multiple = self.tables.multiple.slice(uvwz[1], uvwz[3]);
        // Interleaved per texel, [single; multiple], so one filter serves both.
        let mut scattering = Vec::with_capacity(2 * single.len());
        for (a, b) in single.chunks(n).zip(multiple.chunks(n)) {
            scattering.extend_from_slice(a);
            scattering.extend_from_slice(b);
        }
        SkySlice {
            r,
            mu_s,
            scattering,
            mie: self.tables.single_mie.slice(uvwz[1], uvwz[3]),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn combined_scattering_sliced(
        &self,
        lk: &Lookup,
        slice: Option<&SkySlice>,
        r: f64,
        mu: f64,
        mu_s: f64,
        nu: f64,
        ground: bool,
        scat: &mut [f64],
        mie: &mut [f64],
    ) {
        let slice = slice.filter(|s| s.r == r && s.mu_s == mu_s);
        let uvwz = match slice {
            // The slice already filtered (μ_s, r): only u_ν and u_μ are needed.
            Some(_) => [
                crate::lut::params::u_nu(mu, mu_s, nu),
                0.0,
                crate::lut::params::scattering_u_mu(&lk.radii, &lk.sizes, r, mu, ground),
                0.0,
            ],
            None => {
                crate::lut::params::scattering_uvwz(&lk.radii, &lk.sizes, r, mu, mu_s, nu, ground)
            }
        };
        let n = scat.len();
        let mut both = [0.0f64; 128];
        match slice {
            Some(s) => {
                self.tables.scattering.sample_slice_channels_into(
                    &s.scattering,
                    2 * n,
                    uvwz[0],
                    uvwz[2],
                    &mut both[..2 * n],
                );
                scat.copy_from_slice(&both[..n]);
            }
            None => {
                self.tables.scattering.sample_into(uvwz, scat);
                self.tables.multiple.sample_into(uvwz, &mut both[n..2 * n]);
            }
        }
        // Multiple scattering is stored as radiance; callers apply the molecular phase
        // function to `scat`, so it goes in divided by it.
        let p = self.rayleigh_phase(nu).max(1e-30);
        for k in 0..n {
            scat[k] += both[n + k] / p;
        }
        match self.tables.config.mie {
            MieStorage::Separate => match slice {
                Some(s) => self
                    .tables
                    .single_mie
                    .sample_slice_into(&s.mie, uvwz[0], uvwz[2], mie),
                None => self.tables.single_mie.sample_into(uvwz, mie),
            },
            MieStorage::RedOnly => {
                let mut red = [0.0];
                match slice {
                    Some(s) => self
                        .tables
                        .single_mie
                        .sample_slice_into(&s.mie, uvwz[0], uvwz[2], &mut red),
                    None => self.tables.single_mie.sample_into(uvwz, &mut red),
                }
                for k in 0..n {
                    mie[k] = if scat[0] > 0.0 {
                        scat[k] * red[0] / scat[0] * self.tables.mie_ratio[k]
                    } else {
                        0.0
                    };
                }
            }
        }
    }

    /// Moves a camera in space to where the view ray enters the atmosphere.
    /// Returns (camera, r, rmu) or None when the ray misses the atmosphere.
    fn enter_atmosphere(&self, camera: Vec3, view: Vec3) -> Option<(Vec3, f64, f64)> {
        let top = self.model.top_radius_m;
        let r = length(camera);
        let rmu = dot(camera, view);
        let disc = rmu * rmu - r * r + top * top;
        if r <= top {
            return Some((camera, r, rmu));
        }
        if disc < 0.0 {
            return None;
        }
        let d = -rmu - disc.sqrt();
        if d <= 0.0 {
            return None;
        }
        let c = [
            camera[0] + view[0] * d,
            camera[1] + view[1] * d,
            camera[2] + view[2] * d,
        ];
        Some((c, top, rmu + d))
    }

    /// Sky radiance (W·m⁻²·sr⁻¹·nm⁻¹) seen from `camera` along `view` to the atmosphere
    /// boundary or the ground (ground radiance itself excluded), and the transmittance along
    /// the ray (0 where it hits the ground). `shadow_length_m` ignores in-scattering over the
    /// first metres of the ray (light shafts, paper eq. 17–18).
    pub fn sky_radiance(
        &self,
        camera: Vec3,
        view: Vec3,
        shadow_length_m: f64,
        sun: Vec3,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        self.sky_radiance_sliced(
            None,
            camera,
            view,
            shadow_length_m,
            sun,
            radiance,
            transmittance,
        )
    }

    /// As [`Sky::sky_radiance`], using a [`SkySlice`] for the camera end when it matches.
    #[allow(clippy::too_many_arguments)]
    pub fn sky_radiance_sliced(
        &self,
        slice: Option<&SkySlice>,
        camera: Vec3,
        view: Vec3,
        shadow_length_m: f64,
        sun: Vec3,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        let n = self.channels();
        let Some((camera, r, rmu)) = self.enter_atmosphere(camera, view) else {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance.iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let lk = self.lookup();
        let mu = (rmu / r).clamp(-1.0, 1.0);
        let mu_s = (dot(camera, sun) / r).clamp(-1.0, 1.0);
        let nu = dot(view, sun).clamp(-1.0, 1.0);
        let ground = ray_intersects_ground(r, mu, self.model.bottom_radius_m);
        // An empty `transmittance` asks for radiance only (saves a lookup per sky pixel).
        if transmittance.is_empty() {
        } else if ground {
            transmittance[..n].iter_mut().for_each(|v| *v = 0.0);
        } else {
            lk.transmittance_to_top(r, mu, transmittance);
        }
        let mut scat = [0.0f64; 64];
        let mut mie = [0.0f64; 64];
        let (scat, mie) = (&mut scat[..n], &mut mie[..n]);
        if shadow_length_m <= 0.0 {
            self.combined_scattering_sliced(&lk, slice, r, mu, mu_s, nu, ground, scat, mie);
        } else {
            let d = shadow_length_m;
            let (r_p, mu_p) = crate::geometry::advance(
                r,
                mu,
                d,
                self.model.bottom_radius_m,
                self.model.top_radius_m,
            );
            let mu_s_p = ((r * mu_s + d * nu) / r_p).clamp(-1.0, 1.0);
            self.combined_scattering_sliced(&lk, None, r_p, mu_p, mu_s_p, nu, ground, scat, mie);
            let mut t = [0.0f64; 64];
            lk.transmittance(r, mu, d, ground, &mut t[..n]);
            for k in 0..n {
                scat[k] *= t[k];
                mie[k] *= t[k];
            }
        }
        let (pr, pm) = (self.rayleigh_phase(nu), self.mie_phase(nu));
        for k in 0..n {
            radiance[k] = scat[k] * pr + mie[k] * pm;
        }
    }

    /// In-scattered radiance between `camera` and `point` (aerial perspective) and the
    /// transmittance between them (paper eq. 16's S|x − T(x,x_s)·S|x_s).
    pub fn sky_radiance_to_point(
        &self,
        camera: Vec3,
        point: Vec3,
        shadow_length_m: f64,
        sun: Vec3,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        self.sky_radiance_to_point_sliced(
            None,
            camera,
            point,
            shadow_length_m,
            sun,
            radiance,
            transmittance,
        )
    }

    /// As [`Sky::sky_radiance_to_point`], using a [`SkySlice`] for the camera end when it matches.
    #[allow(clippy::too_many_arguments)]
    pub fn sky_radiance_to_point_sliced(
        &self,
        slice: Option<&SkySlice>,
        camera: Vec3,
        point: Vec3,
        shadow_length_m: f64,
        sun: Vec3,
        radiance: &mut [f64],
        transmittance: &mut [f64],
    ) {
        let n = self.channels();
        let dir = crate::geometry::normalize([
            point[0] - camera[0],
            point[1] - camera[1],
            point[2] - camera[2],
        ]);
        let Some((camera, r, rmu)) = self.enter_atmosphere(camera, dir) else {
            radiance[..n].iter_mut().for_each(|v| *v = 0.0);
            transmittance[..n].iter_mut().for_each(|v| *v = 1.0);
            return;
        };
        let lk = self.lookup();
        let (bottom, top) = (self.model.bottom_radius_m, self.model.top_radius_m);
        let mu = (rmu / r).clamp(-1.0, 1.0);
        let mu_s = (dot(camera, sun) / r).clamp(-1.0, 1.0);
        let nu = dot(dir, sun).clamp(-1.0, 1.0);
        let d_total = length([
            point[0] - camera[0],
            point[1] - camera[1],
            point[2] - camera[2],
        ]);
        let ground = ray_intersects_ground(r, mu, bottom);
        lk.transmittance(r, mu, d_total, ground, transmittance);
        let mut buf = [[0.0f64; 64]; 4];
        let [scat, mie, scat_p, mie_p] = &mut buf;
        let (scat, mie, scat_p, mie_p) = (
            &mut scat[..n],
            &mut mie[..n],
            &mut scat_p[..n],
            &mut mie_p[..n],
        );
        self.combined_scattering_sliced(&lk, slice, r, mu, mu_s, nu, ground, scat, mie);
        let d = (d_total - shadow_length_m.max(0.0)).max(0.0);
        let (r_p, mu_p) = crate::geometry::advance(r, mu, d, bottom, top);
        let mu_s_p = ((r * mu_s + d * nu) / r_p).clamp(-1.0, 1.0);
        self.combined_scattering_sliced(&lk, None, r_p, mu_p, mu_s_p, nu, ground, scat_p, mie_p);
        let mut t_p = [0.0f64; 64];
        let t_p = &mut t_p[..n];
        if shadow_length_m > 0.0 {
            lk.transmittance(r, mu, d, ground, t_p);
        } else {
            t_p.copy_from_slice(&transmittance[..n]);
        }
        // Bruneton 2017: fade single Mie when the sun is below the horizon (table artefacts).
        let fade = smoothstep(0.0, 0.01, mu_s);
        let (pr, pm) = (self.rayleigh_phase(nu), self.mie_phase(nu));
        for k in 0..n {
            let s = (scat[k] - t_p[k] * scat_p[k]).max(0.0);
            let m = (mie[k] - t_p[k] * mie_p[k]).max(0.0) * fade;
            radiance[k] = s * pr + m * pm;
        }
    }

    /// Transmittance between two points inside the atmosphere (the segment must not cross
    /// the ground).
    pub fn transmittance_between(&self, a: Vec3, b: Vec3, out: &mut [f64]) {
        let dir = crate::geometry::normalize([b[0] - a[0], b[1] - a[1], b[2] - a[2]]);
        let r = length(a);
        let mu = dot(a, dir) / r;
        let d = length([b[0] - a[0], b[1] - a[1], b[2] - a[2]]);
        let ground = ray_intersects_ground(r, mu, self.model.bottom_radius_m);
        self.lookup().transmittance(r, mu, d, ground, out);
    }

    /// Transmittance from `point` to the sun, including the planet's occlusion of the disk.
    pub fn transmittance_to_sun(&self, point: Vec3, sun: Vec3, out: &mut [f64]) {
        let r = length(point);
        let lk = self.lookup();
        if r > self.model.top_radius_m {
            // Above the atmosphere: enter it along the sun ray, or see the sun unobstructed.
            if let Some((p, r2, rmu)) = self.enter_atmosphere(point, sun) {
                let _ = p;
                lk.transmittance_to_sun(r2, (rmu / r2).clamp(-1.0, 1.0), out);
            } else {
                out.iter_mut().for_each(|v| *v = 1.0);
            }
            return;
        }
        lk.transmittance_to_sun(r, (dot(point, sun) / r).clamp(-1.0, 1.0), out);
    }

    /// Sun and sky irradiance (W·m⁻²·nm⁻¹) on a surface at `point` with unit `normal`
    /// (Bruneton 2017 `GetSunAndSkyIrradiance`; the sky term with the (1 + n·n̄)/2
    /// occlusion factor of paper eq. 16).
    pub fn sun_and_sky_irradiance(
        &self,
        point: Vec3,
        normal: Vec3,
        sun: Vec3,
        sun_out: &mut [f64],
        sky_out: &mut [f64],
    ) {
        let n = self.channels();
        let lk = self.lookup();
        let r = length(point).clamp(self.model.bottom_radius_m, self.model.top_radius_m);
        let mu_s = (dot(point, sun) / length(point)).clamp(-1.0, 1.0);
        lk.irradiance(&self.tables.irradiance, r, mu_s, sky_out);
        let occlusion = (1.0 + dot(normal, point) / length(point)) * 0.5;
        sky_out[..n].iter_mut().for_each(|v| *v *= occlusion);
        lk.transmittance_to_sun(r, mu_s, sun_out);
        let cos = dot(normal, sun).max(0.0);
        for k in 0..n {
            sun_out[k] *= self.model.solar_irradiance[k] * cos;
        }
    }

    /// Radiance (W·m⁻²·sr⁻¹·nm⁻¹) at the centre of the solar disk outside the atmosphere:
    /// the irradiance divided by the disk's limb-darkening-weighted solid angle.
    pub fn solar_radiance_centre(&self, out: &mut [f64]) {
        for (k, o) in out.iter_mut().enumerate().take(self.channels()) {
            let l = self.model.wavelengths.nm()[k];
            *o = self.model.solar_irradiance[k]
                / disk_solid_angle_weighted(
                    self.model.sun_angular_radius_rad,
                    self.model.limb_darkening,
                    l,
                );
        }
    }
}

/// The scattering tables filtered at one (r, μ_s): see [`Sky::slice`].
pub struct SkySlice {
    r: f64,
    mu_s: f64,
    scattering: Vec<f64>,
    mie: Vec<f64>,
}

/// Neckel (1996), Solar Physics 167, 223–248, eq. 2 and Table II: I(μ)/I(1) =
/// Σ a_k μ^k with a_k = A_k + B_k/λ + C_k/λ⁵ (λ in µm), valid 422.5–1100 nm; shorter
/// wavelengths use 422.5 nm.
pub fn limb_darkening(law: LimbDarkening, mu: f64, lambda_nm: f64) -> f64 {
    match law {
        LimbDarkening::None => 1.0,
        LimbDarkening::Neckel1996 => {
            let mu = mu.clamp(0.0, 1.0);
            let mut s = 0.0;
            let mut p = 1.0;
            for c in limb_darkening_coefficients(law, lambda_nm) {
                s += c * p;
                p *= mu;
            }
            s.max(0.0)
        }
    }
}

/// The polynomial coefficients a_0..a_5 of [`limb_darkening`] at `lambda_nm`
/// (I(μ)/I(1) = max(Σ a_k μ^k, 0), μ clamped to [0, 1]); `[1, 0, …]` without darkening.
/// For backends that evaluate the law themselves (the GPU renderer).
pub fn limb_darkening_coefficients(law: LimbDarkening, lambda_nm: f64) -> [f64; 6] {
    match law {
        LimbDarkening::None => [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        LimbDarkening::Neckel1996 => {
            let l = (lambda_nm.clamp(422.5, 1100.0)) / 1000.0;
            let l5 = l.powi(5);
            [
                0.75267 - 0.265577 / l,
                0.93874 + 0.265577 / l - 0.004095 / l5,
                -1.89287 + 0.012582 / l5,
                2.42234 - 0.017117 / l5,
                -1.71150 + 0.011977 / l5,
                0.49062 - 0.003347 / l5,
            ]
        }
    }
}

/// ∫_disk I(μ)/I(1) dΩ for a disk of angular radius α (sr): E = L_centre × this.
pub fn disk_solid_angle_weighted(alpha: f64, law: LimbDarkening, lambda_nm: f64) -> f64 {
    // θ from the disk centre; on the solar sphere μ = cos of the emergence angle =
    // sqrt(1 − (sin θ / sin α)²).
    let steps = 512;
    let mut s = 0.0;
    for i in 0..steps {
        let theta = (i as f64 + 0.5) / steps as f64 * alpha;
        let x = theta.sin() / alpha.sin();
        let mu = safe_sqrt(1.0 - x * x);
        s += limb_darkening(law, mu, lambda_nm) * theta.sin();
    }
    2.0 * PI * s * alpha / steps as f64
}
