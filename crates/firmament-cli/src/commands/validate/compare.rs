//! One configuration (observer, sun, views): a method's radiance against the reference's,
//! view by view, as relative errors and as the records of the JSON file.

use firmament::math::Vec3;
use firmament::reference::RadianceEstimate;
use firmament::scene::Light;
use firmament::sky::{Shadow, SkyMethod};
use firmament::spectrum::ColourMatrix;
use serde::Serialize;

use super::summary::RelativeErrors;
use super::views::View;
use super::Candidate;

/// A view in the JSON file: where it points, the reference, each table configuration.
#[derive(Debug, Serialize)]
pub struct ViewRecord {
    pub elevation_deg: f64,
    pub azimuth_from_sun_deg: f64,
    pub sun_distance_deg: f64,
    pub reference: ReferenceRecord,
    pub tables: Vec<TableRecord>,
}

/// The reference's estimate of a view (radiance, stderr, samples) and its luminance.
#[derive(Debug, Serialize)]
pub struct ReferenceRecord {
    #[serde(flatten)]
    pub estimate: RadianceEstimate,
    pub luminance_cd_m2: f64,
    pub luminance_stderr: f64,
}

/// One method's answer for a view.
#[derive(Debug, Serialize)]
pub struct TableRecord {
    pub method: &'static str,
    /// The 4D tables' orders (null for other methods).
    pub orders: Option<usize>,
    pub radiance: Vec<f64>,
    pub luminance_cd_m2: f64,
    /// `null` where the reference luminance is 0.
    pub relative_error_luminance: Option<f64>,
    /// Per wavelength; `null` where the reference radiance is 0.
    pub relative_error: Vec<Option<f64>>,
}

impl ViewRecord {
    /// The record of `view` with its reference estimate, no tables yet.
    pub fn new(view: &View, estimate: RadianceEstimate, colour: &ColourMatrix) -> ViewRecord {
        let (luminance_cd_m2, luminance_stderr) =
            colour.luminance_and_stderr(&estimate.radiance, &estimate.stderr);
        ViewRecord {
            elevation_deg: view.elevation_deg,
            azimuth_from_sun_deg: view.azimuth_from_sun_deg,
            sun_distance_deg: view.sun_distance_deg,
            reference: ReferenceRecord {
                estimate,
                luminance_cd_m2,
                luminance_stderr,
            },
            tables: Vec::new(),
        }
    }
}

/// `sky` (the method of `candidate`) seen from `camera` with the sun in `sun`, against the
/// reference of each view in `records` (in the order of `views`): the relative errors, and
/// a [`TableRecord`] added to each record.
pub fn compare_method(
    sky: &dyn SkyMethod,
    candidate: &Candidate,
    colour: &ColourMatrix,
    camera: Vec3,
    sun: Vec3,
    views: &[View],
    records: &mut [ViewRecord],
) -> RelativeErrors {
    let channels = sky.model().channels();
    let mut errors = RelativeErrors::new(channels);
    let (mut radiance, mut transmittance) = (vec![0.0; channels], vec![0.0; channels]);
    let light = Light::sun(sky.model(), sun, false);
    let sky_view = sky.view(camera, &light);
    for (view, record) in views.iter().zip(records.iter_mut()) {
        sky_view.sky_radiance(view.dir, Shadow::None, &mut radiance, &mut transmittance);
        let reference = &record.reference;
        let (y_ref, y_ref_stderr) = (reference.luminance_cd_m2, reference.luminance_stderr);
        let y_table = colour.to_xyz(&radiance)[1];
        if y_ref > 0.0 {
            errors.luminance.push(y_table / y_ref - 1.0);
            errors.luminance_stderr.push(y_ref_stderr / y_ref);
        }
        let mut channel_errors = vec![None; channels];
        for k in 0..channels {
            let (l_ref, l_ref_stderr) =
                (reference.estimate.radiance[k], reference.estimate.stderr[k]);
            if l_ref > 0.0 {
                let error = radiance[k] / l_ref - 1.0;
                errors.channels[k].0.push(error);
                errors.channels[k].1.push(l_ref_stderr / l_ref);
                channel_errors[k] = Some(error);
            }
        }
        record.tables.push(TableRecord {
            method: candidate.method.name(),
            orders: candidate.orders,
            radiance: radiance.clone(),
            luminance_cd_m2: y_table,
            relative_error_luminance: (y_ref > 0.0).then(|| y_table / y_ref - 1.0),
            relative_error: channel_errors,
        });
    }
    errors
}
