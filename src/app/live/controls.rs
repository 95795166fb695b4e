//! The controls of live mode, generated from the scenario document itself: every number the
//! file gives under a pose's `mean`/`cov` or an operation key that
//! [`OPERATION_KINDS`](crate::input::scenario::OPERATION_KINDS) lists for its kind, plus the `[scenario]` settings, the methods and
//! the `[draw]` switches. Nothing here lists operation keys a second time.
//!
//! A control's id is its place in the file in the lowering's words (`pose[0].cov.std_deg[2]`,
//! `operation[1].noise.std[0]`, `scenario.samples`, `draw.clouds`, `scenario.methods.first_order`),
//! so an error about it names the same field.

use serde::Serialize;
use toml_edit::{DocumentMut, Item, Value};

use crate::input::scenario::OperationKind;
use crate::input::scenario::schema::DrawSpec;
use crate::lie::GroupKind;
use crate::plan::limits;
use crate::uncertain::Method;

/// One control of the page.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Control {
    /// Its place in the file, e.g. `pose[0].cov.std_deg[2]` (see the module docs).
    pub id: String,
    /// The heading it is shown under, e.g. `pose map_from_robot`.
    pub section: String,
    /// Its name in the section, e.g. `cov σ θ`.
    pub label: String,
    /// The unit of the value as the file writes it (`m`, `°`, `rad`, or empty).
    pub unit: &'static str,
    /// What kind of value, with its current value and slider range.
    pub kind: ControlKind,
}

/// A control's value.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum ControlKind {
    /// A number with a slider from `min` to `max` in steps of `step` (any typed value is
    /// accepted and validated as in a file).
    Number {
        /// The current value.
        value: f64,
        /// Slider start.
        min: f64,
        /// Slider end.
        max: f64,
        /// Slider step.
        step: f64,
        /// Whether the file needs a whole number here.
        integer: bool,
    },
    /// An on/off switch.
    Toggle {
        /// The current value.
        value: bool,
    },
}

/// Where a control lives in the document.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Place {
    /// A number already in the file, addressed by keys and indices from the root.
    Leaf(Vec<Seg>),
    /// `[scenario]` `samples`, `seed` or `confidence` (inserted when the file has none).
    Setting(&'static str),
    /// A method in `[scenario] methods`.
    Method(Method),
    /// A `[draw]` switch (inserted when the file has none).
    Switch(&'static str),
}

/// One step of a path into the document.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Seg {
    Key(String),
    Index(usize),
}

/// A control and where it lives.
pub(super) struct Slot {
    pub control: Control,
    pub place: Place,
}

/// The `[scenario]` settings offered as controls, with their defaults.
const SETTINGS: [&str; 3] = ["samples", "seed", "confidence"];

/// Every control of `doc` (an already valid scenario of group `group`), in file order:
/// settings, the methods among `applicable` (those that apply to its operations), draw
/// switches, then each pose and operation.
pub(super) fn slots(doc: &DocumentMut, group: GroupKind, applicable: &[Method]) -> Vec<Slot> {
    let mut out = Vec::new();
    let header = doc.get("scenario").and_then(Item::as_table_like);
    for key in SETTINGS {
        let current = header.and_then(|h| h.get(key)).and_then(Item::as_value);
        out.push(Slot {
            control: setting_control(key, current.and_then(number)),
            place: Place::Setting(key),
        });
    }
    let methods = header.map(methods_of).unwrap_or_default();
    let offered = Method::ALL
        .into_iter()
        .filter(|m| *m != Method::Exact && applicable.contains(m));
    for method in offered {
        let slug = method.slug();
        out.push(Slot {
            control: Control {
                id: format!("scenario.methods.{slug}"),
                section: "methods".into(),
                label: method.label().into(),
                unit: "",
                kind: ControlKind::Toggle {
                    value: methods.iter().any(|m| m == slug),
                },
            },
            place: Place::Method(method),
        });
    }
    let draw = doc.get("draw").and_then(Item::as_table_like);
    for switch in DrawSpec::SWITCHES {
        let value = draw
            .and_then(|d| d.get(switch))
            .and_then(Item::as_bool)
            .unwrap_or(true);
        out.push(Slot {
            control: Control {
                id: format!("draw.{switch}"),
                section: "draw".into(),
                label: switch.replace('_', " "),
                unit: "",
                kind: ControlKind::Toggle { value },
            },
            place: Place::Switch(switch),
        });
    }
    poses(doc, group, &mut out);
    operations(doc, group, &mut out);
    out
}

/// The method names in a `[scenario]` table's `methods` array, in file order.
pub(super) fn methods_of(header: &dyn toml_edit::TableLike) -> Vec<String> {
    header
        .get("methods")
        .and_then(Item::as_array)
        .map(|a| {
            a.iter()
                .filter_map(|v| v.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

fn setting_control(key: &'static str, value: Option<f64>) -> Control {
    let (value, min, max, step, integer) = match key {
        "samples" => {
            let v = value.unwrap_or(crate::app::DEFAULT_SAMPLES as f64);
            let max = (4.0 * v).clamp(20_000.0, limits::MAX_SAMPLES as f64);
            (v, 100.0, max, 100.0, true)
        }
        "seed" => (value.unwrap_or(0.0), 0.0, 1000.0, 1.0, true),
        _ => (
            value.unwrap_or(crate::uncertain::Confidence::DEFAULT.get()),
            0.5,
            0.999,
            0.001,
            false,
        ),
    };
    Control {
        id: format!("scenario.{key}"),
        section: "scenario".into(),
        label: key.into(),
        unit: "",
        kind: ControlKind::Number {
            value,
            min,
            max,
            step,
            integer,
        },
    }
}

/// Each `[[pose]]`'s `mean` and `cov` numbers.
fn poses(doc: &DocumentMut, group: GroupKind, out: &mut Vec<Slot>) {
    let Some(poses) = doc.get("pose").and_then(Item::as_array_of_tables) else {
        return;
    };
    for (i, pose) in poses.iter().enumerate() {
        let name = pose.get("name").and_then(Item::as_str).unwrap_or("?");
        let section = format!("pose {name}");
        for key in ["mean", "cov"] {
            let Some(forms) = pose.get(key).and_then(Item::as_table_like) else {
                continue;
            };
            let rotation_first =
                forms.get("order").and_then(Item::as_str) == Some("rotation_first");
            for (form, item) in forms.iter() {
                let Some(value) = item.as_value() else {
                    continue;
                };
                let path = vec![
                    Seg::Key("pose".into()),
                    Seg::Index(i),
                    Seg::Key(key.into()),
                    Seg::Key(form.into()),
                ];
                let meaning = Meaning::of(key, form, group, rotation_first);
                leaves(value, path, &section, &meaning, out);
            }
        }
    }
}

/// Each `[[operation]]`'s numbers under the keys its kind takes.
fn operations(doc: &DocumentMut, group: GroupKind, out: &mut Vec<Slot>) {
    let Some(ops) = doc.get("operation").and_then(Item::as_array_of_tables) else {
        return;
    };
    for (i, op) in ops.iter().enumerate() {
        let kind = op.get("kind").and_then(Item::as_str).unwrap_or("?");
        let output = op.get("output").and_then(Item::as_str).unwrap_or("?");
        let Some(OperationKind {
            required, optional, ..
        }) = OperationKind::named(kind)
        else {
            continue;
        };
        let section = format!("operation[{i}] {kind} → {output}");
        for key in required.iter().chain(optional.iter()) {
            let Some(item) = op.get(key) else { continue };
            let base = vec![
                Seg::Key("operation".into()),
                Seg::Index(i),
                Seg::Key((*key).into()),
            ];
            if let Some(table) = item.as_table_like() {
                // A covariance given inline (`noise = { std = […] }`).
                let rotation_first =
                    table.get("order").and_then(Item::as_str) == Some("rotation_first");
                for (form, inner) in table.iter() {
                    let Some(value) = inner.as_value() else {
                        continue;
                    };
                    let mut path = base.clone();
                    path.push(Seg::Key(form.into()));
                    let meaning = Meaning::of("cov", form, group, rotation_first);
                    let meaning = Meaning {
                        prefix: format!("{key} {}", meaning.prefix),
                        ..meaning
                    };
                    leaves(value, path, &section, &meaning, out);
                }
            } else if let Some(value) = item.as_value() {
                let meaning = Meaning::operation_key(key);
                leaves(value, base, &section, &meaning, out);
            }
        }
    }
}

/// What the numbers of one key mean: their labels, units and whether they are spreads.
struct Meaning {
    /// Shown before each component's name (`cov σ`, `mean`, `noise σ`).
    prefix: String,
    /// Name and unit of component `j` of a flat array (else `[j]`).
    components: Vec<(&'static str, &'static str)>,
    /// Unit of every value when `components` does not say.
    unit: &'static str,
    /// A standard deviation or other nonnegative size: the slider starts at 0.
    spread: bool,
    /// An angle: the slider spans a turn.
    angle: Option<Angle>,
    /// A whole number (a step count).
    whole: bool,
}

#[derive(Clone, Copy, PartialEq)]
enum Angle {
    Degrees,
    Radians,
}

impl Meaning {
    fn of(key: &str, form: &str, group: GroupKind, rotation_first: bool) -> Self {
        let degrees = form.ends_with("_deg");
        let rot_unit = if degrees { "°" } else { "rad" };
        let mut m = Meaning {
            prefix: key.to_owned(),
            components: Vec::new(),
            unit: "",
            spread: false,
            angle: None,
            whole: false,
        };
        match (key, form) {
            ("cov", "std" | "std_deg") => {
                m.prefix = "σ".into();
                m.spread = true;
                m.components = tangent_names(group, rot_unit, rotation_first);
            }
            ("cov", _) => m.prefix = format!("Σ {form}"),
            (_, "xy_theta" | "xy_theta_deg") => {
                m.components = vec![("x", "m"), ("y", "m"), ("θ", rot_unit)];
            }
            (_, "angle" | "angle_deg") => m.components = vec![("θ", rot_unit)],
            (_, "xyz") => m.components = vec![("x", "m"), ("y", "m"), ("z", "m")],
            (_, "rpy" | "rpy_deg") => {
                m.components = vec![("roll", rot_unit), ("pitch", rot_unit), ("yaw", rot_unit)];
            }
            (_, "quaternion_xyzw") => {
                m.components = vec![("qx", ""), ("qy", ""), ("qz", ""), ("qw", "")];
            }
            (_, "axis_angle") => {
                m.components = vec![
                    ("axis x", ""),
                    ("axis y", ""),
                    ("axis z", ""),
                    ("angle", "rad"),
                ];
            }
            _ => m.prefix = format!("{key} {form}"),
        }
        if m.components.is_empty() && form.ends_with("_deg") {
            m.angle = Some(Angle::Degrees);
        }
        m
    }

    fn operation_key(key: &str) -> Self {
        let (unit, spread) = match key {
            "wheel_radius" | "wheelbase" => ("m", true),
            "duration" | "dt" => ("s", true),
            "speed" => ("m/s", false),
            "turn_rate" => ("rad/s", false),
            "diffusion" => ("", true),
            "steps" => ("", true),
            _ => ("", false),
        };
        Meaning {
            prefix: key.to_owned(),
            components: Vec::new(),
            unit,
            spread,
            angle: None,
            whole: key == "steps",
        }
    }
}

/// Names and units of the tangent components `[ρ; θ]` of `group` (rotation first if asked).
fn tangent_names(
    group: GroupKind,
    rot_unit: &'static str,
    rotation_first: bool,
) -> Vec<(&'static str, &'static str)> {
    let (rho, theta): (&[&'static str], &[&'static str]) = match group {
        GroupKind::So2 => (&[], &["θ"]),
        GroupKind::Se2 => (&["x", "y"], &["θ"]),
        GroupKind::So3 => (&[], &["θx", "θy", "θz"]),
        GroupKind::Se3 => (&["x", "y", "z"], &["θx", "θy", "θz"]),
    };
    let rho = rho.iter().map(|n| (*n, "m"));
    let theta = theta.iter().map(|n| (*n, rot_unit));
    if rotation_first {
        theta.chain(rho).collect()
    } else {
        rho.chain(theta).collect()
    }
}

/// The numbers in `value` (a number, an array of them, or an array of arrays).
fn leaves(value: &Value, path: Vec<Seg>, section: &str, meaning: &Meaning, out: &mut Vec<Slot>) {
    let mut push = |path: Vec<Seg>, label: String, unit: &'static str, angle, v: &Value| {
        let Some(x) = number(v) else { return };
        // The file format's only whole numbers below `[scenario]` are step counts.
        let integer = meaning.whole;
        let (min, max, step) = range(x, integer, meaning.spread, angle);
        out.push(Slot {
            control: Control {
                id: id_of(&path),
                section: section.to_owned(),
                label,
                unit,
                kind: ControlKind::Number {
                    value: x,
                    min,
                    max,
                    step,
                    integer,
                },
            },
            place: Place::Leaf(path),
        });
    };
    match value {
        Value::Array(items) => {
            for (j, item) in items.iter().enumerate() {
                let mut p = path.clone();
                p.push(Seg::Index(j));
                match item {
                    Value::Array(row) => {
                        for (k, v) in row.iter().enumerate() {
                            let mut p = p.clone();
                            p.push(Seg::Index(k));
                            let label = format!("{} [{j}][{k}]", meaning.prefix);
                            push(p, label, meaning.unit, meaning.angle, v);
                        }
                    }
                    v => {
                        let (label, unit, angle) = match meaning.components.get(j) {
                            Some((name, unit)) => {
                                (format!("{} {name}", meaning.prefix), *unit, angle_of(unit))
                            }
                            None => (
                                format!("{} [{j}]", meaning.prefix),
                                meaning.unit,
                                meaning.angle,
                            ),
                        };
                        push(p, label, unit, angle, v);
                    }
                }
            }
        }
        v => {
            let (label, unit, angle) = match meaning.components.first() {
                Some((name, unit)) => (format!("{} {name}", meaning.prefix), *unit, angle_of(unit)),
                None => (meaning.prefix.clone(), meaning.unit, meaning.angle),
            };
            push(path, label, unit, angle, v);
        }
    }
}

fn angle_of(unit: &str) -> Option<Angle> {
    match unit {
        "°" => Some(Angle::Degrees),
        "rad" => Some(Angle::Radians),
        _ => None,
    }
}

/// A number of the document (integers as `f64`).
pub(super) fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Float(f) => Some(*f.value()),
        Value::Integer(i) => Some(*i.value() as f64),
        _ => None,
    }
}

/// A slider around the file's value `x`: spreads from 0 to 4x; angles over a turn (or 4x
/// for an angular spread); whole numbers from 1; other numbers x ± 2|x| (at least ± 1).
fn range(x: f64, integer: bool, spread: bool, angle: Option<Angle>) -> (f64, f64, f64) {
    let (min, max) = match (spread, angle) {
        (true, _) if integer => (1.0, (4.0 * x).max(10.0)),
        (true, Some(Angle::Degrees)) => (0.0, (4.0 * x).clamp(10.0, 180.0).max(x)),
        (true, Some(Angle::Radians)) => (0.0, (4.0 * x).clamp(0.2, 3.2).max(x)),
        (true, None) => (0.0, if x > 0.0 { 4.0 * x } else { 1.0 }),
        (false, Some(Angle::Degrees)) => ((-180.0_f64).min(x), 180.0_f64.max(x)),
        (false, Some(Angle::Radians)) => ((-3.2_f64).min(x), 3.2_f64.max(x)),
        (false, None) => {
            let r = (2.0 * x.abs()).max(1.0);
            (x - r, x + r)
        }
    };
    let step = if integer {
        1.0
    } else {
        nice_step((max - min) / 400.0)
    };
    (min, max, step)
}

/// The largest 1, 2 or 5 × 10ᵏ not above `raw`.
fn nice_step(raw: f64) -> f64 {
    if raw.is_nan() || raw <= 0.0 || raw.is_infinite() {
        return 0.001;
    }
    let p = 10f64.powf(raw.log10().floor());
    [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * p)
        .find(|s| *s <= raw)
        .unwrap_or(p)
}

/// `pose[0].cov.std_deg[2]`: keys joined by dots, indices in brackets.
pub(super) fn id_of(path: &[Seg]) -> String {
    let mut s = String::new();
    for seg in path {
        match seg {
            Seg::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(k);
            }
            Seg::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_read_like_the_lowerings_fields() {
        let path = [
            Seg::Key("pose".into()),
            Seg::Index(0),
            Seg::Key("cov".into()),
            Seg::Key("std_deg".into()),
            Seg::Index(2),
        ];
        assert_eq!(id_of(&path), "pose[0].cov.std_deg[2]");
    }

    #[test]
    fn steps_are_round() {
        assert_eq!(nice_step(0.3), 0.2);
        assert_eq!(nice_step(0.07), 0.05);
        assert_eq!(nice_step(1.0), 1.0);
        assert_eq!(nice_step(0.0), 0.001);
    }

    #[test]
    fn an_angular_spread_spans_four_times_the_file_value() {
        assert_eq!(range(20.0, false, true, Some(Angle::Degrees)).1, 80.0);
        assert_eq!(range(3.0, true, true, None), (1.0, 12.0, 1.0));
    }

    #[test]
    fn an_angle_spans_a_turn_around_zero() {
        assert_eq!(range(30.0, false, false, Some(Angle::Degrees)).0, -180.0);
        assert_eq!(range(0.0, false, false, Some(Angle::Radians)).0, -3.2);
        assert_eq!(range(-200.0, false, false, Some(Angle::Degrees)).0, -200.0);
    }
}
