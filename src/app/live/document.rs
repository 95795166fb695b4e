//! The scenario being edited live: the file's text, the current document (a `toml_edit`
//! document, so comments and layout survive every edit), and the input lowered from it.
//!
//! Every edit is applied to a copy of the document, printed, and loaded by the same path as a
//! file ([`load_text`]); only when that succeeds does the copy become
//! current. A bad value is refused with the file's field and message, and nothing changes.

use toml_edit::{Array, DocumentMut, Item, Value};

use super::controls::{self, Control, ControlKind, Place, Seg, Slot};
use super::prose;
use crate::app::{AppError, Loaded, load_text};
use crate::uncertain::Method;

/// Monte Carlo samples of the evaluation that checks an edited file before it is accepted.
const EDIT_CHECK_SAMPLES: u64 = 16;

/// A change asked for by the page (or a test): a control's id and its new value.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
pub struct Edit {
    /// The control's id, e.g. `pose[0].cov.std_deg[2]`.
    pub id: String,
    /// The new value.
    pub value: EditValue,
}

/// A number or a switch, as the page sends it. A number field the user cleared arrives as
/// `null` ([`EditValue::Empty`]), a typed text that is no JSON number as a string
/// ([`EditValue::Text`]); both are refused naming the field, as is NaN.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(untagged)]
pub enum EditValue {
    /// For a number control.
    Number(f64),
    /// For a toggle.
    Toggle(bool),
    /// A number typed as text (`"1e-3"`, `"NaN"`): read as a number, else refused.
    Text(String),
    /// A cleared field (`null`): refused, naming the field.
    Empty,
}

/// Why an edit was refused. The document is unchanged.
#[derive(Debug, thiserror::Error)]
pub enum EditError {
    /// No control has this id.
    #[error("{id}: no such control (the page offers only the scenario's values)")]
    Unknown {
        /// The id asked for.
        id: String,
    },
    /// A number for a switch, or the reverse; a fraction or out-of-range integer where the
    /// file needs a whole number.
    #[error("{id}: {message}")]
    Value {
        /// The control.
        id: String,
        /// What is wrong.
        message: String,
    },
    /// The edited file does not load: the lowering's message, with its field.
    #[error(transparent)]
    Invalid(#[from] AppError),
}

impl EditError {
    /// The field the error is about (the control id, or the file's key named by the
    /// lowering, e.g. `pose[0].cov`), when known.
    pub fn field(&self) -> Option<String> {
        match self {
            EditError::Unknown { id } | EditError::Value { id, .. } => Some(id.clone()),
            EditError::Invalid(AppError::Input(crate::input::scenario::ScenarioError::At {
                field,
                ..
            })) => Some(field.clone()),
            EditError::Invalid(_) => None,
        }
    }
}

/// A scenario file open for live editing.
pub struct LiveDocument {
    origin: String,
    source: String,
    doc: DocumentMut,
    loaded: Loaded,
    /// The controls as the file has them (what [`changes`] compares with).
    file_controls: Vec<Control>,
    /// The methods that apply to the scenario ([`applicable_methods`]): the only ones offered.
    methods: Vec<Method>,
}

impl LiveDocument {
    /// Parses and loads scenario `text` (`origin` names it in messages).
    ///
    /// # Errors
    /// The file's error, as `posecov check` reports it.
    ///
    /// ```
    /// use posecov::app::live::LiveDocument;
    /// let text = posecov::input::scenario::bundled::find("camera_on_robot").unwrap().text;
    /// let live = LiveDocument::new(text, "camera_on_robot.toml").unwrap();
    /// assert!(live.controls().iter().any(|c| c.id == "pose[0].cov.std_deg[2]"));
    /// ```
    pub fn new(text: &str, origin: &str) -> Result<Self, AppError> {
        let loaded = load_text(text, origin)?;
        let doc = parse(text, origin)?;
        let methods = applicable_methods(&loaded);
        let mut live = Self {
            origin: origin.to_owned(),
            source: text.to_owned(),
            doc,
            loaded,
            file_controls: Vec::new(),
            methods,
        };
        live.file_controls = live.controls();
        Ok(live)
    }

    /// Opens a bundled scenario by name or a scenario file (`.toml`); other inputs are
    /// refused with a message saying live mode edits scenario files only.
    ///
    /// # Errors
    /// [`AppError::Live`] for an input that is not a scenario file; the file's error.
    pub fn open(name_or_path: &str) -> Result<Self, AppError> {
        // Found and its format decided by the one place that does ([`crate::input::locate`]);
        // the loader's message lists the bundled names.
        let located = crate::input::locate(name_or_path)?;
        if located.format != crate::input::Format::Scenario {
            return Err(AppError::Live(format!(
                "{name_or_path}: live mode edits scenario files (.toml) only; \
                 show other inputs with `posecov {name_or_path}`"
            )));
        }
        match &located.place {
            crate::input::Place::Bundled(e) => {
                Self::new(e.text, &format!("{}.toml (bundled)", e.name))
            }
            crate::input::Place::File(path) => {
                let text = std::fs::read_to_string(path).map_err(|e| {
                    crate::input::scenario::ScenarioError::Read {
                        path: name_or_path.to_owned(),
                        reason: e.to_string(),
                    }
                })?;
                Self::new(&text, name_or_path)
            }
            crate::input::Place::Live(url) => Err(AppError::Live(format!(
                "{url}: live mode edits scenario files; show a running robot with `posecov {url}`"
            ))),
        }
    }

    /// The controls for the current document.
    pub fn controls(&self) -> Vec<Control> {
        self.slots().into_iter().map(|s| s.control).collect()
    }

    fn slots(&self) -> Vec<Slot> {
        self.slots_of(&self.doc)
    }

    fn slots_of(&self, doc: &DocumentMut) -> Vec<Slot> {
        use crate::lie::GroupKind;
        use crate::plan::AnyPlan;
        let group = match &self.loaded.input.plan {
            AnyPlan::So2(_) => GroupKind::So2,
            AnyPlan::Se2(_) => GroupKind::Se2,
            AnyPlan::So3(_) => GroupKind::So3,
            AnyPlan::Se3(_) => GroupKind::Se3,
        };
        controls::slots(doc, group, &self.methods)
    }

    /// The current input (always valid).
    pub fn loaded(&self) -> &Loaded {
        &self.loaded
    }

    /// The current text: the file with every edit applied, its comments and layout kept.
    pub fn text(&self) -> String {
        self.doc.to_string()
    }

    /// The name used in messages (the file, or `name.toml (bundled)`).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Applies `edit` if the edited file loads, evaluates and draws (a quick pass with few
    /// samples); else returns why and changes nothing.
    ///
    /// # Errors
    /// [`EditError`], naming the control or the file's field.
    ///
    /// ```
    /// use posecov::app::live::{Edit, EditValue, LiveDocument};
    /// let mut live = LiveDocument::open("camera_on_robot").unwrap();
    /// let bad = Edit { id: "pose[0].cov.std_deg[2]".into(), value: EditValue::Number(-1.0) };
    /// let e = live.apply(&bad).unwrap_err();
    /// assert_eq!(e.field().as_deref(), Some("pose[0].cov"), "{e}");
    /// let good = Edit { id: "pose[0].cov.std_deg[2]".into(), value: EditValue::Number(40.0) };
    /// live.apply(&good).unwrap();
    /// assert!(live.text().contains("std_deg = [0.05, 0.05, 40.0] }   # x, y in metres"));
    /// ```
    pub fn apply(&mut self, edit: &Edit) -> Result<(), EditError> {
        let slot = self
            .slots()
            .into_iter()
            .find(|s| s.control.id == edit.id)
            .ok_or_else(|| EditError::Unknown {
                id: edit.id.clone(),
            })?;
        let mut doc = self.doc.clone();
        write(&mut doc, &slot, &edit.value)?;
        let now: Vec<Control> = self.slots_of(&doc).into_iter().map(|s| s.control).collect();
        restate_words(&mut doc, &self.source, &self.file_controls, &now);
        let text = doc.to_string();
        let mut loaded = load_text(&text, &self.origin)?;
        // The file's checks pass; its numbers must also evaluate and draw (a control of 1e16
        // overflows only there), as `posecov check` would find. A quick pass, few samples.
        let quick = crate::app::Overrides {
            samples: Some(EDIT_CHECK_SAMPLES),
            ..Default::default()
        };
        crate::app::pipeline(&loaded, &quick, None).map_err(|e| EditError::Value {
            id: edit.id.clone(),
            message: format!("the file with this value does not evaluate: {e}"),
        })?;
        self.doc = doc;
        let note = changes(&self.file_controls, &self.controls());
        loaded.input.about.description.push_str(&note);
        self.loaded = loaded;
        Ok(())
    }

    /// Returns to the file's values.
    pub fn reset(&mut self) -> Result<(), AppError> {
        let text = self.source.clone();
        self.replace_source(&text)
    }

    /// Replaces the file's text (the file changed on disk, `--watch`): the new text becomes
    /// both the current document and what [`reset`](Self::reset) returns to.
    ///
    /// # Errors
    /// The new text's error; nothing changes then.
    pub fn replace_source(&mut self, text: &str) -> Result<(), AppError> {
        let next = Self::new(text, &self.origin)?;
        *self = next;
        Ok(())
    }
}

/// The methods that apply to `loaded`'s operations: those its evaluation with every method
/// asked for (and a few samples) ran or reported failing
/// ([`AnyEvaluation::methods_that_ran`](crate::eval::AnyEvaluation::methods_that_ran), the one
/// rule). Should that evaluation fail, every method is offered, as before.
fn applicable_methods(loaded: &Loaded) -> Vec<Method> {
    let quick = crate::app::Overrides {
        samples: Some(EDIT_CHECK_SAMPLES),
        ..Default::default()
    };
    crate::app::resolve(&loaded.input, &quick, None)
        .ok()
        .and_then(|mut settings| {
            settings.eval.methods = Method::ALL.to_vec();
            crate::app::evaluate(loaded, &settings.eval).ok()
        })
        .map_or_else(|| Method::ALL.to_vec(), |e| e.methods_that_ran())
}

/// The values changed from the file, as a paragraph for the description (the file's prose
/// still speaks of the file's values): "**Changed live:** pose map_from_robot σ θ = 40°
/// (file: 20°); …". Empty when nothing differs.
///
/// ```
/// use posecov::app::live::{Edit, EditValue, LiveDocument};
/// let mut live = LiveDocument::open("camera_on_robot").unwrap();
/// live.apply(&Edit { id: "pose[0].cov.std_deg[2]".into(), value: EditValue::Number(40.0) }).unwrap();
/// let text = &live.loaded().input.about.description;
/// assert!(text.ends_with("**Changed live:** pose map_from_robot σ θ = 40° (file: 20°)."), "{text}");
/// ```
fn changes(file: &[Control], now: &[Control]) -> String {
    let value = |c: &Control| match c.kind {
        ControlKind::Number { value, .. } => format!("{}{}", trim(value), c.unit),
        ControlKind::Toggle { value } => (if value { "on" } else { "off" }).to_owned(),
    };
    let differ: Vec<String> = now
        .iter()
        .filter_map(|c| {
            let was = file.iter().find(|f| f.id == c.id)?;
            (was.kind != c.kind).then(|| {
                format!(
                    "{} {} = {} (file: {})",
                    c.section,
                    c.label,
                    value(c),
                    value(was)
                )
            })
        })
        .collect();
    if differ.is_empty() {
        String::new()
    } else {
        format!("\n\n**Changed live:** {}.", differ.join("; "))
    }
}

/// Restates the numbers of `[scenario]`'s title and description (the file's, in `source`)
/// that state a value edited from `file` to `now` ([`prose::restate`]), keeping the file's
/// quoting and layout.
fn restate_words(doc: &mut DocumentMut, source: &str, file: &[Control], now: &[Control]) {
    let Ok(file_doc) = source.parse::<DocumentMut>() else {
        return;
    };
    for key in ["title", "description"] {
        let raw = match file_doc.get("scenario").and_then(|s| s.get(key)) {
            Some(Item::Value(Value::String(f))) => f.display_repr().into_owned(),
            _ => continue,
        };
        let Ok(new) = prose::restate(&raw, file, now).parse::<Value>() else {
            continue;
        };
        if let Some(old) = doc
            .get_mut("scenario")
            .and_then(|s| s.get_mut(key))
            .and_then(Item::as_value_mut)
        {
            replace(old, new);
        }
    }
}

/// A number in six significant digits, without trailing zeros: `40`, `0.05`, `0.3` (for
/// 0.30000000000000004), `1.5e-5`.
pub(super) fn trim(x: f64) -> String {
    let magnitude = x.abs();
    if x == 0.0 || !x.is_finite() {
        return x.to_string();
    }
    let short = |digits: &str| {
        if digits.contains('.') {
            digits
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_owned()
        } else {
            digits.to_owned()
        }
    };
    if !(1e-4..1e6).contains(&magnitude) {
        let sci = format!("{x:.5e}");
        let (mantissa, exponent) = sci.split_once('e').unwrap_or((&sci, "0"));
        return format!("{}e{exponent}", short(mantissa));
    }
    let decimals = (5 - magnitude.log10().floor() as i32).clamp(0, 9) as usize;
    short(&format!("{x:.decimals$}"))
}

fn parse(text: &str, origin: &str) -> Result<DocumentMut, AppError> {
    // The text already loaded, so this only fails on a bug; report it like a file error.
    text.parse::<DocumentMut>()
        .map_err(|e| AppError::Live(format!("{origin}: {e}")))
}

/// Writes `value` into `doc` where `slot` lives, keeping the old value's decoration
/// (spacing and trailing comment).
fn write(doc: &mut DocumentMut, slot: &Slot, value: &EditValue) -> Result<(), EditError> {
    let id = &slot.control.id;
    let wrong = |message: &str| EditError::Value {
        id: id.clone(),
        message: message.to_owned(),
    };
    let value = number_of(&slot.control, value)?;
    match (&slot.control.kind, value) {
        (ControlKind::Number { integer, .. }, EditValue::Number(x)) => {
            let new = if *integer {
                if x.fract() != 0.0 || !x.is_finite() || x < 0.0 || x > i64::MAX as f64 {
                    return Err(wrong(&format!("{x} is not a whole number ≥ 0")));
                }
                Value::from(x as i64)
            } else {
                // TOML has nan and inf; the lowering refuses them with the field named.
                Value::from(x)
            };
            match &slot.place {
                Place::Leaf(path) => {
                    let old =
                        leaf_mut(doc, path).ok_or_else(|| wrong("is no longer in the file"))?;
                    if controls::number(old) == Some(x) {
                        // Unchanged: keep the file's spelling (`0.062110`, `1e-3`).
                        return Ok(());
                    }
                    // A whole number written as an integer stays one (TOML floats accept it).
                    let new = if old.is_integer() && x.fract() == 0.0 && x.abs() < 1e15 {
                        Value::from(x as i64)
                    } else {
                        new
                    };
                    replace(old, new);
                }
                Place::Setting(key) => set_key(doc, "scenario", key, new),
                _ => return Err(wrong("is a switch; send true or false")),
            }
        }
        (ControlKind::Toggle { .. }, EditValue::Toggle(on)) => match &slot.place {
            Place::Switch(key) => set_key(doc, "draw", key, Value::from(on)),
            Place::Method(method) => set_method(doc, *method, on),
            _ => return Err(wrong("is a number")),
        },
        (ControlKind::Number { .. }, EditValue::Toggle(_)) => {
            return Err(wrong("is a number; send a number"));
        }
        (ControlKind::Toggle { .. }, _) => {
            return Err(wrong("is a switch; send true or false"));
        }
        (ControlKind::Number { .. }, _) => return Err(wrong("is a number; type one")),
    }
    Ok(())
}

/// A number control's value as a number, or why not in the field's words: a cleared field, a
/// text that is no number, NaN or an infinity name the field (`pose[0].cov.std_deg[2]: pose
/// map_from_robot σ θ is empty: type a number`). Switches keep their value.
fn number_of(control: &Control, value: &EditValue) -> Result<EditValue, EditError> {
    let ControlKind::Number { .. } = control.kind else {
        return match value {
            EditValue::Toggle(_) | EditValue::Number(_) => Ok(value.clone()),
            EditValue::Text(_) | EditValue::Empty => Err(EditError::Value {
                id: control.id.clone(),
                message: format!(
                    "{} {} is a switch: on or off",
                    control.section, control.label
                ),
            }),
        };
    };
    let field = format!("{} {}", control.section, control.label);
    let refuse = |message: String| EditError::Value {
        id: control.id.clone(),
        message,
    };
    let x = match value {
        EditValue::Number(x) => *x,
        EditValue::Toggle(_) => return Ok(value.clone()),
        EditValue::Empty => return Err(refuse(format!("{field} is empty: type a number"))),
        EditValue::Text(t) if t.trim().is_empty() => {
            return Err(refuse(format!("{field} is empty: type a number")));
        }
        EditValue::Text(t) => t
            .trim()
            .parse::<f64>()
            .map_err(|_| refuse(format!("{field}: `{t}` is not a number")))?,
    };
    if !x.is_finite() {
        return Err(refuse(format!(
            "{field}: {x} is not a number; type a finite one"
        )));
    }
    Ok(EditValue::Number(x))
}

/// Replaces `old` by `new`, keeping `old`'s spacing and comment.
fn replace(old: &mut Value, mut new: Value) {
    *new.decor_mut() = old.decor().clone();
    *old = new;
}

/// Sets `[table] key = value`, creating the table or key when the file has none.
fn set_key(doc: &mut DocumentMut, table: &str, key: &str, value: Value) {
    let item = doc
        .as_table_mut()
        .entry(table)
        .or_insert_with(|| Item::Table(toml_edit::Table::new()));
    let Some(t) = item.as_table_like_mut() else {
        return;
    };
    match t.get_mut(key).and_then(Item::as_value_mut) {
        Some(old) => replace(old, value),
        None => {
            t.insert(key, Item::Value(value));
        }
    }
}

/// Adds `method` to `[scenario] methods` or removes it, keeping the others' order.
fn set_method(doc: &mut DocumentMut, method: Method, on: bool) {
    let slug = method.slug();
    let header = doc
        .as_table_mut()
        .entry("scenario")
        .or_insert_with(|| Item::Table(toml_edit::Table::new()));
    let Some(h) = header.as_table_like_mut() else {
        return;
    };
    let mut names = controls::methods_of(h);
    names.retain(|n| n != slug);
    if on {
        names.push(slug.to_owned());
    }
    let array: Array = names.iter().map(String::as_str).collect();
    match h.get_mut("methods").and_then(Item::as_value_mut) {
        Some(old) => replace(old, Value::Array(array)),
        None => {
            h.insert("methods", Item::Value(Value::Array(array)));
        }
    }
}

/// The number at `path` (keys and indices from the root).
fn leaf_mut<'a>(doc: &'a mut DocumentMut, path: &[Seg]) -> Option<&'a mut Value> {
    let (Seg::Key(first), rest) = path.split_first()? else {
        return None;
    };
    let value = item_leaf(doc.as_table_mut().get_mut(first)?, rest)?;
    controls::number(value).is_some().then_some(value)
}

/// Tables and arrays of tables first, then values.
fn item_leaf<'a>(item: &'a mut Item, rest: &[Seg]) -> Option<&'a mut Value> {
    match (item, rest) {
        (Item::ArrayOfTables(a), [Seg::Index(i), Seg::Key(k), tail @ ..]) => {
            item_leaf(a.get_mut(*i)?.get_mut(k)?, tail)
        }
        (Item::Table(t), [Seg::Key(k), tail @ ..]) => item_leaf(t.get_mut(k)?, tail),
        (Item::Value(v), tail) => value_leaf(v, tail),
        _ => None,
    }
}

fn value_leaf<'a>(value: &'a mut Value, rest: &[Seg]) -> Option<&'a mut Value> {
    match (value, rest) {
        (v, []) => Some(v),
        (Value::InlineTable(t), [Seg::Key(k), tail @ ..]) => value_leaf(t.get_mut(k)?, tail),
        (Value::Array(a), [Seg::Index(i), tail @ ..]) => value_leaf(a.get_mut(*i)?, tail),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::trim;

    #[test]
    fn numbers_read_as_typed() {
        assert_eq!(trim(40.0), "40");
        assert_eq!(trim(0.05), "0.05");
        assert_eq!(trim(0.1 + 0.2), "0.3");
        assert_eq!(trim(-1.25), "-1.25");
        assert_eq!(trim(123_456.0), "123456");
        assert_eq!(trim(0.0), "0");
        assert_eq!(trim(1.5e-5), "1.5e-5");
        assert_eq!(trim(2e7), "2e7");
    }
}
