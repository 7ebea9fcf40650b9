//! χ² tests of the guide's sampling, alone and mixed with BSDFs, of its training's
//! independence from the order of records, and of the spreading of records over regions.

use glam::{Vec2, Vec3};

use super::quadtree::{Distribution, to_sphere};
use super::{Guide, GuidedBsdf, Record};
use crate::geometry::Aabb;
use crate::render::bsdf::Bsdf;
use crate::render::chi_square::sphere_z_score;
use crate::render::sampler::Sampler;
use crate::scene::Pbr;

/// The guide's share in the mixtures tested (the paper's fixed α).
const SHARE: f32 = 0.5;

/// Radiance piled towards two directions, one below the horizon, over a faint floor.
fn radiance(d: Vec3) -> f32 {
    let a = Vec3::new(0.3, -0.5, 0.81).normalize();
    let b = Vec3::new(-0.6, 0.2, -0.77).normalize();
    0.01 + 50.0 * d.dot(a).max(0.0).powi(40) + 5.0 * d.dot(b).max(0.0).powi(8)
}

/// A distribution learned from [`radiance`] over five passes, each drawing its records
/// from the previous pass's distribution (as training does) and refining after.
fn learned() -> Distribution {
    let mut distribution = Distribution::uniform();
    for pass in 0..5u32 {
        let histogram = distribution.refined();
        for i in 0..20_000u64 {
            let mut sampler = Sampler::for_sample(u64::from(pass), 0, i as u32);
            let (d, pdf) = distribution.sample(sampler.uniform2());
            histogram.record(d, radiance(d) / pdf);
        }
        distribution = histogram.freeze();
    }
    distribution
}

#[test]
fn the_learned_distribution_samples_as_its_pdf_says() {
    let distribution = learned();
    let mut i = 0u64;
    let (z, chi2, dof) = sphere_z_score(
        400_000,
        || {
            i += 1;
            let (d, pdf) = distribution.sample(Sampler::for_sample(9, 0, i as u32).uniform2());
            let at = distribution.pdf(d);
            assert!(
                (pdf - at).abs() <= 1e-3 * at,
                "{d}: sampled {pdf}, pdf {at}"
            );
            Some(d)
        },
        |d| distribution.pdf(d),
    );
    assert!(z < 4.5, "χ² {chi2:.1} with {dof} dof (z {z:.2})");
    // It learned: the brighter direction is far more likely than the floor.
    let peak = distribution.pdf(Vec3::new(0.3, -0.5, 0.81).normalize());
    let floor = distribution.pdf(Vec3::new(0.0, 1.0, 0.0));
    assert!(peak > 50.0 * floor, "peak {peak}, floor {floor}");
}

#[test]
fn guided_bsdfs_sample_as_their_mixed_pdf_says() {
    let distribution = learned();
    let rough_glass = Pbr {
        transmission: 1.0,
        roughness: 0.4,
        metallic: 0.0,
        ..Pbr::diffuse(Vec3::ONE)
    };
    let cases = [
        (
            "Lambertian",
            Bsdf::new(&Pbr::diffuse(Vec3::splat(0.7)), true),
        ),
        ("rough glass", Bsdf::new(&rough_glass, true)),
    ];
    let n = Vec3::Z;
    for (name, bsdf) in &cases {
        let guided = GuidedBsdf {
            bsdf,
            guide: Some(&distribution),
            fraction: SHARE,
        };
        for mu in [0.3f32, 0.9] {
            let wo = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let mut i = 0u64;
            let (z, chi2, dof) = sphere_z_score(
                400_000,
                || {
                    i += 1;
                    let mut sampler = Sampler::for_sample(3, 0, i as u32);
                    let (s, (guide_pdf, bsdf_pdf)) =
                        guided.sample_with_densities(n, wo, &mut sampler)?;
                    let pdf = guided.pdf(n, wo, s.wi);
                    // The densities a training record keeps are the guide's and the BSDF's.
                    let expected = (distribution.pdf(s.wi), bsdf.pdf(n, wo, s.wi));
                    assert!(
                        (guide_pdf - expected.0).abs() <= 1e-3 * expected.0
                            && (bsdf_pdf - expected.1).abs() <= 1e-3 * expected.1,
                        "{name}: densities {guide_pdf}, {bsdf_pdf} vs {expected:?}"
                    );
                    assert!(
                        (s.pdf - pdf).abs() <= 1e-3 * pdf,
                        "{name}: {} vs {pdf}",
                        s.pdf
                    );
                    let weight = bsdf.eval(n, wo, s.wi) / pdf;
                    assert!(
                        (s.weight - weight).abs().max_element() <= 1e-3 * weight.max_element(),
                        "{name}: weight {} vs f/pdf {weight}",
                        s.weight
                    );
                    Some(s.wi)
                },
                // Directions the BSDF gives nothing end the path (no sample): expected
                // only where it scatters.
                |wi| {
                    if bsdf.eval(n, wo, wi) == Vec3::ZERO {
                        0.0
                    } else {
                        guided.pdf(n, wo, wi)
                    }
                },
            );
            assert!(
                z < 4.5,
                "{name}, μo {mu}: χ² {chi2:.1} with {dof} dof (z {z:.2})"
            );
        }
    }
}

#[test]
fn the_mixed_pdf_integrates_to_the_bsdfs_share_plus_the_guides() {
    // Over the sphere the mixture integrates to α + (1 − α)·(the BSDF's non-delta mass):
    // 1 for a Lambertian surface.
    let distribution = learned();
    let bsdf = Bsdf::new(&Pbr::diffuse(Vec3::splat(0.5)), true);
    let guided = GuidedBsdf {
        bsdf: &bsdf,
        guide: Some(&distribution),
        fraction: SHARE,
    };
    let wo = Vec3::new(0.6, 0.0, 0.8);
    let n = 512;
    let mut integral = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let p = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            integral += f64::from(guided.pdf(Vec3::Z, wo, to_sphere(p)));
        }
    }
    integral *= 4.0 * std::f64::consts::PI / (n * n) as f64;
    assert!((integral - 1.0).abs() < 5e-3, "∫ pdf = {integral}");
}

/// Records spread over the bounds split the spatial tree; each record is then added to the
/// region at a point drawn within a box the size of its own region around its vertex,
/// always the same point for the same record, and often in a neighbouring region.
#[test]
fn records_are_splatted_within_a_region_of_their_vertex() {
    let mut guide = Guide::new(Aabb {
        min: Vec3::ZERO,
        max: Vec3::ONE,
    });
    let records: Vec<Record> = (0..20_000u32)
        .map(|i| {
            let mut sampler = Sampler::for_sample(5, 0, i);
            let p = Vec3::new(sampler.uniform(), sampler.uniform(), sampler.uniform());
            let w = Vec3::ONE;
            Guide::record(p, Vec3::Z, (1.0, 1.0, 1.0), (w, w), Vec3::ZERO)
        })
        .collect();
    guide.add_path(&records, Vec3::ONE);
    guide.end_pass(0);
    assert!(guide.regions.len() >= 16, "{} regions", guide.regions.len());
    let mut moved = 0;
    for r in &records {
        let size = guide.region_size(r.point);
        let offset = guide.splat_offset(r);
        assert!(
            offset.abs().cmple(0.5 * size).all(),
            "offset {offset} for a region of {size}"
        );
        assert_eq!(offset, guide.splat_offset(r));
        moved += usize::from(guide.splat_region(r) != guide.region_index(r.point));
    }
    // Between a unit cube of regions where every face leads to a neighbour (a uniform
    // offset within ±½ a region moves 1 − (¾)³ = 37/64 of the records) and none: the
    // bounds' own faces keep what crosses them.
    let share = moved as f64 / records.len() as f64;
    assert!(
        share > 0.2 && share < 37.0 / 64.0,
        "{share} of records moved"
    );
}
