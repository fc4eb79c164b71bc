//! Log–log figures for the benchmarks (PNG through plotters). Text uses the DejaVu
//! Sans font shipped in assets/fonts, registered once, so figures look the same on
//! every machine and need no system font library.

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// One line of a figure: its legend label and points (x, y, label beside the point).
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64, String)>,
}

/// A dashed guide line of slope `slope` in log–log axes through (x0, y0).
pub struct Guide {
    pub label: String,
    pub slope: f64,
    pub through: (f64, f64),
}

pub struct Figure<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub series: &'a [Series],
    pub guides: &'a [Guide],
}

/// Twelve distinguishable colours, enough for one line per validation scene.
const PALETTE: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(0, 0, 0),
    RGBColor(127, 127, 127),
    RGBColor(0, 90, 50),
];

/// Positive finite points only: a log axis has no place for the rest.
fn plottable(s: &Series) -> impl Iterator<Item = &(f64, f64, String)> {
    s.points
        .iter()
        .filter(|(x, y, _)| x.is_finite() && y.is_finite() && *x > 0.0 && *y > 0.0)
}

/// Axis range padded by a fraction of a decade on each side.
fn log_range(values: impl Iterator<Item = f64>) -> Option<std::ops::Range<f64>> {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() || hi <= 0.0 {
        return None;
    }
    let pad = 10f64.powf(0.15);
    let (lo, hi) = if hi / lo < 1.5 {
        (lo / 2.0, hi * 2.0)
    } else {
        (lo, hi)
    };
    Some(lo / pad..hi * pad)
}

/// Draw `fig` as a 900×640 PNG at `path`. A figure with no plottable point is not
/// written (Ok(false)).
pub fn log_log(path: &std::path::Path, fig: &Figure) -> Result<bool, String> {
    REGISTER.call_once(|| {
        let _ = register_font("sans-serif", FontStyle::Normal, FONT);
    });
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let xs = fig.series.iter().flat_map(|s| plottable(s).map(|p| p.0));
    let ys = fig.series.iter().flat_map(|s| plottable(s).map(|p| p.1));
    let (Some(xr), Some(yr)) = (log_range(xs), log_range(ys)) else {
        return Ok(false);
    };
    let root = BitMapBackend::new(path, (900, 640)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(fig.title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(xr.clone().log_scale(), yr.clone().log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(fig.x_label)
        .y_desc(fig.y_label)
        // Log axes label their minor ticks too: six keeps a decade's labels apart.
        .x_labels(6)
        .y_labels(8)
        .x_label_formatter(&|v| format!("{v:.1e}"))
        .y_label_formatter(&|v| format!("{v:.1e}"))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| err(&e))?;
    for g in fig.guides {
        // The segment inside both ranges: plotters does not clip a line whose ends
        // lie outside a log axis correctly.
        let (x0, y0) = g.through;
        let x_at = |y: f64| x0 * (y / y0).powf(1.0 / g.slope);
        let (ya, yb) = (x_at(yr.start), x_at(yr.end));
        let (lo, hi) = (xr.start.max(ya.min(yb)), xr.end.min(ya.max(yb)));
        if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            continue;
        }
        let at = |x: f64| (x, y0 * (x / x0).powf(g.slope));
        let line = [at(lo), at(hi)];
        chart
            .draw_series(DashedLineSeries::new(
                line,
                6,
                4,
                BLACK.mix(0.4).stroke_width(1),
            ))
            .map_err(|e| err(&e))?
            .label(g.label.as_str())
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.mix(0.4)));
    }
    for (k, s) in fig.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> = plottable(s).map(|p| (p.0, p.1)).collect();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))
            .map_err(|e| err(&e))?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
            .map_err(|e| err(&e))?;
        chart
            .draw_series(plottable(s).filter(|p| !p.2.is_empty()).map(|p| {
                let font = ("sans-serif", 12).into_font().color(&colour);
                EmptyElement::at((p.0, p.1)) + Text::new(p.2.clone(), (7, -14), font)
            }))
            .map_err(|e| err(&e))?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(true)
}
