//! Log–log figures for the benchmarks (PNG through plotters). Text uses the DejaVu
//! Sans font shipped in assets/fonts, registered once, so figures look the same on
//! every machine and need no system font library.

use plotters::element::DashedPathElement;
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

/// Pixel sizes, chosen so that a figure shrunk to a paper's column width (about
/// 8 cm) still has text of a readable size.
const WIDTH: u32 = 1000;
const HEIGHT: u32 = 720;
const CAPTION_PX: u32 = 26;
const AXIS_DESC_PX: u32 = 21;
const TICK_PX: u32 = 20;
const LEGEND_PX: u32 = 18;
const POINT_LABEL_PX: u32 = 15;

/// `n` in Unicode superscript digits (DejaVu Sans has them): 10⁻³.
fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(DIGITS[c.to_digit(10).unwrap() as usize]);
    }
    s
}

/// m × 10^k with m an integer 1..9 (a tick), or None.
fn mantissa_exponent(v: f64) -> Option<(u32, i32)> {
    let k = v.log10().floor() as i32;
    let m = v / 10f64.powi(k);
    let (m, k) = if m.round() >= 10.0 {
        (1.0, k + 1)
    } else {
        (m.round(), k)
    };
    ((v / (m * 10f64.powi(k)) - 1.0).abs() < 1e-9).then_some((m as u32, k))
}

/// A log axis' tick label: 10ᵏ at a decade, m×10ᵏ between.
fn log_label(v: f64) -> String {
    match mantissa_exponent(v) {
        Some((1, k)) => format!("10{}", superscript(k)),
        Some((m, k)) => format!("{m}×10{}", superscript(k)),
        None => format!("{v:.1e}"),
    }
}

/// Every m × 10^k (m in `mantissas`) inside `r`, ascending.
fn log_points(r: &std::ops::Range<f64>, mantissas: &[u32]) -> Vec<f64> {
    let (k0, k1) = (r.start.log10().floor() as i32, r.end.log10().ceil() as i32);
    let mut v = Vec::new();
    for k in k0..=k1 {
        for &m in mantissas {
            let x = f64::from(m) * 10f64.powi(k);
            if x >= r.start && x <= r.end {
                v.push(x);
            }
        }
    }
    v
}

/// Labelled ticks of a log axis `pixels` long: decades when three fit in the
/// range, else 1–2–5, 1–2–3–5 or every integer mantissa, the first that gives three; then thinned so that no two
/// labels come closer than `room(a, b)` pixels (plotters' own log ticks label
/// the minor ticks too, and their labels ran into each other).
fn log_ticks(r: &std::ops::Range<f64>, pixels: f64, room: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    let sets: [&[u32]; 4] = [
        &[1],
        &[1, 2, 5],
        &[1, 2, 3, 5],
        &[1, 2, 3, 4, 5, 6, 7, 8, 9],
    ];
    let mut ticks = Vec::new();
    for set in sets {
        ticks = log_points(r, set);
        if ticks.len() >= 3 {
            break;
        }
    }
    let px = |v: f64| pixels * (v / r.start).log10() / (r.end / r.start).log10();
    // Decades first, so that thinning keeps 10ᵏ over its neighbours.
    let mut order: Vec<f64> = ticks.clone();
    order.sort_by_key(|&v| mantissa_exponent(v).map_or(10, |(m, _)| m));
    let mut kept: Vec<f64> = Vec::new();
    for v in order {
        if kept.iter().all(|&u| (px(u) - px(v)).abs() >= room(u, v)) {
            kept.push(v);
        }
    }
    kept.sort_by(f64::total_cmp);
    kept
}

/// The dash (length, gap) of guide line `k`, so that two guides tell apart.
fn guide_dash(k: usize) -> (u32, u32) {
    [(10, 5), (3, 4), (16, 4), (6, 3)][k % 4]
}

/// Register the shipped font as "sans-serif" (once per process).
pub fn register_fonts() {
    REGISTER.call_once(|| {
        let _ = register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Draw `fig` as a PNG at `path`. A figure with no plottable point is not
/// written (Ok(false)).
pub fn log_log(path: &std::path::Path, fig: &Figure) -> Result<bool, String> {
    register_fonts();
    let err = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let xs = fig.series.iter().flat_map(|s| plottable(s).map(|p| p.0));
    let ys = fig.series.iter().flat_map(|s| plottable(s).map(|p| p.1));
    let (Some(xr), Some(yr)) = (log_range(xs), log_range(ys)) else {
        return Ok(false);
    };
    let root = BitMapBackend::new(path, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let tick_font = ("sans-serif", TICK_PX).into_font();
    let text_w = |s: &str, font: &FontDesc| {
        let style = TextStyle::from(font.clone());
        root.estimate_text_size(s, &style)
            .map_or(0.0, |(w, _)| f64::from(w))
    };
    // The plot's size before it is built (the figure less margins, caption and
    // label areas): close enough to space the ticks. The y label area is as wide
    // as its widest tick label, so the axis title sits next to the ticks.
    let x_area = TICK_PX + AXIS_DESC_PX + 30;
    let plot_h = f64::from(HEIGHT - x_area - CAPTION_PX - 2 * 20 - 10);
    let y_ticks = log_ticks(&yr, plot_h, |_, _| 1.6 * f64::from(TICK_PX));
    let widest = y_ticks
        .iter()
        .map(|&v| text_w(&log_label(v), &tick_font))
        .fold(0.0, f64::max);
    let y_area = widest as u32 + AXIS_DESC_PX + 30;
    let plot_w = f64::from(WIDTH - y_area - 2 * 20);
    let mut x_ticks = log_ticks(&xr, plot_w, |a, b| {
        (text_w(&log_label(a), &tick_font) + text_w(&log_label(b), &tick_font)) / 2.0 + 16.0
    });
    // A label centred on the axis' right end would run past the figure's edge
    // (the margin is 20 pixels).
    let x_px = |v: f64| plot_w * (v / xr.start).log10() / (xr.end / xr.start).log10();
    x_ticks.retain(|&v| x_px(v) + text_w(&log_label(v), &tick_font) / 2.0 <= plot_w + 16.0);
    let minor = [1, 2, 3, 4, 5, 6, 7, 8, 9];
    let x_coord = xr
        .clone()
        .log_scale()
        .with_key_points(x_ticks)
        .with_light_points(log_points(&xr, &minor));
    let y_coord = yr
        .clone()
        .log_scale()
        .with_key_points(y_ticks)
        .with_light_points(log_points(&yr, &minor));
    let mut chart = ChartBuilder::on(&root)
        .caption(fig.title, ("sans-serif", CAPTION_PX))
        .margin(20)
        .x_label_area_size(x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x_coord, y_coord)
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc(fig.x_label)
        .y_desc(fig.y_label)
        .x_label_formatter(&|v| log_label(*v))
        .y_label_formatter(&|v| log_label(*v))
        .label_style(("sans-serif", TICK_PX))
        .axis_desc_style(("sans-serif", AXIS_DESC_PX))
        .bold_line_style(BLACK.mix(0.25))
        .light_line_style(BLACK.mix(0.07))
        .draw()
        .map_err(|e| err(&e))?;
    for (k, g) in fig.guides.iter().enumerate() {
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
        let (dash, gap) = guide_dash(k);
        let style = BLACK.mix(0.55).stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(line, dash, gap, style))
            .map_err(|e| err(&e))?
            .label(g.label.as_str())
            .legend(move |(x, y)| DashedPathElement::new([(x, y), (x + 24, y)], dash, gap, style));
    }
    let label_font = ("sans-serif", POINT_LABEL_PX).into_font();
    let (base_x, base_y) = chart.plotting_area().get_base_pixel();
    let (area_w, area_h) = chart.plotting_area().dim_in_pixel();
    let (area_w, area_h) = (f64::from(area_w), f64::from(area_h));
    // Every plottable point in the plot's pixels, per series.
    let series_px: Vec<Vec<(f64, f64)>> = fig
        .series
        .iter()
        .map(|s| {
            plottable(s)
                .map(|p| {
                    let (px, py) = chart.backend_coord(&(p.0, p.1));
                    (f64::from(px - base_x), f64::from(py - base_y))
                })
                .collect()
        })
        .collect();
    // Point labels: each goes to the first side of its point (above right, below
    // right, above left, below left) where it overlaps no label placed before it,
    // no other point and, if it can, no line, and stays inside the plot; a label
    // with no such side is left out (points of different kernels at the same Δx
    // and cost say the same).
    let label_h = f64::from(POINT_LABEL_PX);
    let points: Vec<(f64, f64)> = series_px.iter().flatten().copied().collect();
    // The lines, sampled every few pixels: a label prefers a side no line crosses.
    let line_samples: Vec<(f64, f64)> = series_px
        .iter()
        .flat_map(|px| px.windows(2))
        .flat_map(|w| {
            let (p, q) = (w[0], w[1]);
            let n = ((q.0 - p.0).hypot(q.1 - p.1) / 3.0).ceil().max(1.0) as u32;
            (0..=n).map(move |t| {
                let t = f64::from(t) / f64::from(n);
                (p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1))
            })
        })
        .collect();
    let mut placed: Vec<[f64; 4]> = Vec::new(); // x0, y0, x1, y1
    let mut offsets: Vec<Vec<Option<(i32, i32)>>> = Vec::new();
    for (s, px) in fig.series.iter().zip(&series_px) {
        let mut of_series = Vec::new();
        for (p, &(x, y)) in plottable(s).zip(px) {
            if p.2.is_empty() {
                of_series.push(None);
                continue;
            }
            let w = text_w(&p.2, &label_font);
            let sides = [
                (8.0, -4.0 - label_h),
                (8.0, 4.0),
                (-8.0 - w, -4.0 - label_h),
                (-8.0 - w, 4.0),
            ];
            let fits = |&(dx, dy): &(f64, f64), avoid_lines: bool| {
                let r = [x + dx, y + dy, x + dx + w, y + dy + label_h];
                let off_lines = !avoid_lines
                    || line_samples
                        .iter()
                        .all(|&(lx, ly)| lx < r[0] || lx > r[2] || ly < r[1] || ly > r[3]);
                let inside = r[0] >= 0.0 && r[1] >= 0.0 && r[2] <= area_w && r[3] <= area_h;
                let clear = placed
                    .iter()
                    .all(|q| r[2] < q[0] || q[2] < r[0] || r[3] < q[1] || q[3] < r[1]);
                let no_point = points.iter().all(|&(px, py)| {
                    (px, py) == (x, y)
                        || px < r[0] - 5.0
                        || px > r[2] + 5.0
                        || py < r[1] - 5.0
                        || py > r[3] + 5.0
                });
                inside && clear && no_point && off_lines
            };
            let side = (sides.iter().find(|s| fits(s, true)))
                .or_else(|| sides.iter().find(|s| fits(s, false)))
                .copied();
            if let Some((dx, dy)) = side {
                placed.push([x + dx, y + dy, x + dx + w, y + dy + label_h]);
            }
            of_series.push(side.map(|(dx, dy)| (dx.round() as i32, dy.round() as i32)));
        }
        offsets.push(of_series);
    }
    for (k, s) in fig.series.iter().enumerate() {
        let colour = PALETTE[k % PALETTE.len()];
        let pts: Vec<(f64, f64)> = plottable(s).map(|p| (p.0, p.1)).collect();
        chart
            .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(3)))
            .map_err(|e| err(&e))?
            .label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], colour.stroke_width(3)));
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 5, colour.filled())))
            .map_err(|e| err(&e))?;
        let labelled = plottable(s)
            .zip(&offsets[k])
            .filter_map(|(p, o)| o.map(|o| (p, o)));
        chart
            .draw_series(labelled.map(|(p, offset)| {
                let font = label_font.clone().color(&colour);
                EmptyElement::at((p.0, p.1)) + Text::new(p.2.clone(), offset, font)
            }))
            .map_err(|e| err(&e))?;
    }
    // The legend goes into the corner of the plot that covers the fewest points,
    // point labels and line pixels.
    let legend_font = ("sans-serif", LEGEND_PX).into_font();
    let labels: Vec<&str> = fig
        .guides
        .iter()
        .map(|g| g.label.as_str())
        .chain(fig.series.iter().map(|s| s.label.as_str()))
        .collect();
    let legend_w = labels
        .iter()
        .map(|l| text_w(l, &legend_font))
        .fold(0.0, f64::max)
        + 30.0
        + 20.0;
    let legend_h = labels.len() as f64 * 1.25 * f64::from(LEGEND_PX) + 20.0;
    let mut marks: Vec<(f64, f64, f64)> = Vec::new(); // pixel x, y, weight
    for px in &series_px {
        for (p, q) in px.iter().zip(px.iter().skip(1)) {
            for t in 0..40 {
                let t = f64::from(t) / 40.0;
                marks.push((p.0 + t * (q.0 - p.0), p.1 + t * (q.1 - p.1), 1.0));
            }
        }
        marks.extend(px.iter().map(|&(x, y)| (x, y, 20.0)));
    }
    for r in &placed {
        for f in [0.0, 0.5, 1.0] {
            marks.push((r[0] + f * (r[2] - r[0]), (r[1] + r[3]) / 2.0, 5.0));
        }
    }
    let corners = [
        (
            SeriesLabelPosition::UpperRight,
            area_w - legend_w - 5.0,
            5.0,
        ),
        (SeriesLabelPosition::UpperLeft, 5.0, 5.0),
        (
            SeriesLabelPosition::LowerRight,
            area_w - legend_w - 5.0,
            area_h - legend_h - 5.0,
        ),
        (SeriesLabelPosition::LowerLeft, 5.0, area_h - legend_h - 5.0),
    ];
    let covered = |x0: f64, y0: f64| -> f64 {
        marks
            .iter()
            .filter(|m| m.0 >= x0 - 6.0 && m.0 <= x0 + legend_w + 6.0)
            .filter(|m| m.1 >= y0 - 6.0 && m.1 <= y0 + legend_h + 6.0)
            .map(|m| m.2)
            .sum()
    };
    let mut position = SeriesLabelPosition::UpperRight;
    let mut least = f64::INFINITY;
    for (pos, x0, y0) in corners {
        let c = covered(x0, y0);
        if c < least {
            (least, position) = (c, pos);
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.mix(0.4))
        .label_font(legend_font.clone())
        .legend_area_size(30)
        .position(position)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_labels_read_as_powers_of_ten() {
        assert_eq!(log_label(1e-3), "10⁻³");
        assert_eq!(log_label(1.0), "10⁰");
        assert_eq!(log_label(100.0), "10²");
        assert_eq!(log_label(2e-1), "2×10⁻¹");
        assert_eq!(log_label(0.3), "3×10⁻¹");
    }

    #[test]
    fn log_ticks_are_decades_when_three_fit_and_never_crowd() {
        let wide = log_ticks(&(1e-4..5e-1), 800.0, |_, _| 60.0);
        assert_eq!(wide.len(), 4);
        assert!(wide.iter().all(|&v| mantissa_exponent(v).unwrap().0 == 1));
        // Less than a decade and a half: 1-2-5 or finer, at least two labels.
        let narrow = log_ticks(&(0.22..1.4), 800.0, |_, _| 60.0);
        assert!(narrow.len() >= 2, "{narrow:?}");
        let px = |v: f64| 800.0 * (v / 0.22f64).log10() / (1.4f64 / 0.22).log10();
        for w in narrow.windows(2) {
            assert!(px(w[1]) - px(w[0]) >= 60.0, "{narrow:?}");
        }
        // Twelve decades on a short axis: thinned to every other decade or so.
        let many = log_ticks(&(1e-9..1e3), 300.0, |_, _| 40.0);
        assert!(many.len() <= 8 && many.len() >= 3, "{many:?}");
    }
}
