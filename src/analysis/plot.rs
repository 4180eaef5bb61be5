//! The benchmark's picture: relMSE against time on log–log axes, one line
//! per algorithm, as PNG. Text uses the font egui already ships, so no system
//! font is needed.

use std::path::Path;

use plotters::prelude::*;

use super::convergence::ConvergenceLog;

const COLOURS: [RGBColor; 4] =
    [RGBColor(214, 96, 77), RGBColor(67, 147, 195), RGBColor(90, 174, 97), RGBColor(153, 112, 171)];

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

/// Draw `series` (name, log) to `path`, and the reference's noise floor
/// (where a curve that flattens has met the reference, not bias).
pub fn plot_error_against_time(
    title: &str,
    series: &[(String, ConvergenceLog)],
    noise_floor: Option<f64>,
    path: &Path,
) -> Result<(), String> {
    register_font();
    let points: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|(_, log)| log.points.iter().map(|p| (p.seconds, p.error.rel_mse)))
        .filter(|(t, e)| *t > 0.0 && *e > 0.0)
        .collect();
    if points.is_empty() {
        return Err("nothing to plot".into());
    }
    let (t0, t1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (e0, e1) = points.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let floor = noise_floor.filter(|f| *f > 0.0);
    let e0 = floor.map_or(e0, |f| e0.min(f));
    let (width, height) = (900u32, 600u32);
    let mut rgb = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(64)
            .build_cartesian_2d((t0 * 0.8..t1 * 1.25).log_scale(), (e0 * 0.8..e1 * 1.25).log_scale())
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .x_desc("seconds")
            .y_desc("relMSE")
            .x_label_formatter(&|v| format!("{v:.2}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(|e| e.to_string())?;
        for (i, (name, log)) in series.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            let line: Vec<(f64, f64)> = log
                .points
                .iter()
                .filter(|p| p.seconds > 0.0 && p.error.rel_mse > 0.0)
                .map(|p| (p.seconds, p.error.rel_mse))
                .collect();
            chart
                .draw_series(LineSeries::new(line, colour.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(name.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
        }
        if let Some(floor) = floor {
            let grey = RGBColor(120, 120, 120);
            let dashes = (0..40).map(|k| {
                let at = |j: f64| (t0 * 0.8) * ((t1 * 1.25) / (t0 * 0.8)).powf(j / 80.0);
                PathElement::new(vec![(at(2.0 * k as f64), floor), (at(2.0 * k as f64 + 1.0), floor)], grey)
            });
            chart
                .draw_series(dashes)
                .map_err(|e| e.to_string())?
                .label("the reference's own noise")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    crate::render::image::save_png(path, width, height, false, &rgb).map_err(|e| e.to_string())
}
