//! The rough conductor against an independent implementation: Mitsuba 3's
//! `roughconductor` (GGX, visible normals) evaluated on a grid of
//! directions by `tools/mitsuba_bsdf.py`, stored in
//! `tests/data/mitsuba_roughconductor.csv`.

use gi_studio::render::world::materials::Bsdf;
use gi_studio::scene::Metal;
use glam::Vec3;

struct Row {
    metal: String,
    alpha: (f32, f32),
    eta: Vec3,
    k: Vec3,
    wo: Vec3,
    wi: Vec3,
    /// f · cos θi.
    value: Vec3,
    pdf: f32,
}

fn rows() -> Vec<Row> {
    let text = include_str!("data/mitsuba_roughconductor.csv");
    let mut lines = text.lines();
    let header = lines.next().expect("a header");
    assert!(header.starts_with("metal,alpha_u,alpha_v"), "{header}");
    lines
        .map(|line| {
            let mut fields = line.split(',');
            let metal = fields.next().expect("a metal").to_string();
            let x: Vec<f32> = fields.map(|f| f.parse().unwrap_or_else(|e| panic!("{line}: {e}"))).collect();
            assert_eq!(x.len(), 18, "{line}");
            let v = |i: usize| Vec3::new(x[i], x[i + 1], x[i + 2]);
            Row { metal, alpha: (x[0], x[1]), eta: v(2), k: v(5), wo: v(8), wi: v(11), value: v(14), pdf: x[17] }
        })
        .collect()
}

/// `eval` × cos θi and `pdf` equal Mitsuba's within 1e-3 relative (1e-6
/// absolute, for the values at the far edge of a narrow lobe) on 1,000
/// pairs of directions over five surfaces: isotropic α 0.05–1, anisotropic
/// both ways, four measured metals and an index written out.
#[test]
fn the_rough_conductor_is_mitsubas() {
    let rows = rows();
    assert_eq!(rows.len(), 1000);
    let close = |ours: f32, theirs: f32| (ours - theirs).abs() <= 1e-3 * theirs.abs() + 1e-6;
    let (mut lit, mut worst) = (0, 0.0f32);
    for row in &rows {
        let bsdf = Bsdf::conductor(Metal::Custom { eta: row.eta, k: row.k }, row.alpha.0, row.alpha.1);
        let (f, pdf) = bsdf.eval_pdf(row.wo, row.wi, Vec3::Z);
        let value = f * row.wi.z;
        let say = || format!("{} α {:?}, wo {}, wi {}", row.metal, row.alpha, row.wo, row.wi);
        for c in 0..3 {
            assert!(close(value[c], row.value[c]), "{}: f·cos {value} against Mitsuba's {}", say(), row.value);
        }
        assert!(close(pdf, row.pdf), "{}: pdf {pdf} against Mitsuba's {}", say(), row.pdf);
        lit += (row.value.max_element() > 1e-3) as usize;
        if row.value.min_element() > 1e-3 {
            worst = worst.max(((value - row.value) / row.value).abs().max_element());
        }
    }
    println!("worst relative difference where f·cos > 1e-3: {worst:.1e}");
    // The grid holds the lobes, not only their dark edges
    assert!(lit > 500, "only {lit} of the pairs see the lobe");
}

/// The named metals are Mitsuba's measured spectra as its RGB variant
/// reduces them.
#[test]
fn the_named_metals_are_mitsubas() {
    let rows = rows();
    for (name, metal) in [("Au", Metal::Gold), ("Ag", Metal::Silver), ("Cu", Metal::Copper), ("Al", Metal::Aluminium)] {
        let row = rows.iter().find(|r| r.metal == name).unwrap_or_else(|| panic!("no {name} in the data"));
        let (eta, k) = metal.index();
        assert!((eta - row.eta).abs().max_element() < 1e-5 && (k - row.k).abs().max_element() < 1e-5, "{name}");
    }
}
