//! The numbers of axes, grids and scale bars: "nice" steps (1, 2 or 5 × 10ᵏ), their ticks and
//! their labels. Plain arithmetic, shared by the drawing stage (a 3-D view's grid spacing) and
//! every sink (a figure's axes and scale bar).

/// A "nice" step (1, 2 or 5 × 10ᵏ) giving about `count` intervals over `span`.
///
/// ```
/// use posecov::scene::units::nice_step;
/// assert_eq!(nice_step(1.0, 5), 0.2);
/// assert_eq!(nice_step(37.0, 4), 10.0);
/// ```
pub fn nice_step(span: f64, count: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / count.max(1) as f64;
    let power = 10f64.powf(raw.log10().floor());
    let m = raw / power;
    let nice = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    nice * power
}

/// The ticks of `step` inside [lo, hi].
pub fn ticks(lo: f64, hi: f64, step: f64) -> Vec<f64> {
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    if last < first || last - first > 1000 {
        return Vec::new();
    }
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick value with as many decimals as `step` needs.
///
/// ```
/// use posecov::scene::units::tick_label;
/// assert_eq!(tick_label(0.30000000000000004, 0.1), "0.3");
/// assert_eq!(tick_label(-0.0, 0.5), "0");
/// assert_eq!(tick_label(2000.0, 1000.0), "2000");
/// ```
pub fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let text = format!("{:.*}", decimals.min(9), v);
    if text
        .trim_start_matches('-')
        .chars()
        .all(|c| c == '0' || c == '.')
    {
        "0".to_owned()
    } else {
        text
    }
}

/// A length in metres as the scale bar writes it ("0.5 m", "20 mm", "2 km").
///
/// ```
/// use posecov::scene::units::length_label;
/// assert_eq!(length_label(0.5), "0.5 m");
/// assert_eq!(length_label(0.02), "20 mm");
/// assert_eq!(length_label(5000.0), "5 km");
/// ```
pub fn length_label(metres: f64) -> String {
    let (value, unit) = if metres < 0.1 {
        (metres * 1000.0, "mm")
    } else if metres >= 1000.0 {
        (metres / 1000.0, "km")
    } else {
        (metres, "m")
    };
    format!("{} {unit}", tick_label(value, nice_step(value, 1)))
}
