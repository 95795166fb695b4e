//! g2o / GTSAM text: records, tokens and numbers, each error at its line and column.
//!
//! One record per line: a tag and whitespace-separated values; `#` starts a comment. Read:
//! `VERTEX_SE2 id x y θ`, `VERTEX2` (the same), `EDGE_SE2 i j x y θ` + the 6 numbers of the
//! information matrix's upper triangle (xx xy xθ yy yθ θθ), TORO's `EDGE2 i j x y θ` + the same
//! 6 numbers in TORO's order (xx xy yy θθ xθ yθ; [`InformationOrder::Toro`]),
//! `VERTEX_SE3:QUAT id x y z qx qy qz qw`, `EDGE_SE3:QUAT i j x y z qx qy qz qw` + 21 numbers
//! (the upper triangle over (x, y, z, qx, qy, qz)); the priors `EDGE_PRIOR_SE2 id x y θ` + 6
//! and `EDGE_SE3_PRIOR id param x y z qx qy qz qw` + 21 (g2o's `EdgeSE2Prior`,
//! `EdgeSE3Prior`: `param` names a `PARAMS_SE3OFFSET`, read as the identity offset), and
//! `FIX id …` (vertices held at their estimates). Other g2o records posecov does not draw
//! (landmarks, parameters) are counted and skipped; any other first token is an error.

use super::super::{InputError, Locator};
use crate::plan::choices::SkippedRecords;

/// Planar or spatial.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// SE(2) records.
    Planar,
    /// SE(3) records.
    Spatial,
}

/// What a record is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A vertex: id and pose.
    Vertex,
    /// An edge: two ids, measurement and information.
    Edge,
    /// A prior on one vertex (g2o's `EDGE_PRIOR_SE2`; `EDGE_SE3_PRIOR` also names its offset
    /// parameter): id, measurement and information.
    Prior,
    /// g2o's `FIX id …`: vertices held at their estimates.
    Fix,
}

/// How an edge writes its information matrix's entries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InformationOrder {
    /// The upper triangle row by row (g2o, GTSAM): for SE(2) xx xy xθ yy yθ θθ.
    UpperTriangle,
    /// TORO's `EDGE2` (OpenSLAM TORO's file format: `inf_ff inf_fs inf_ss inf_rr inf_fr
    /// inf_sr`, f forward, s sideways, r rotation): xx xy yy θθ xθ yθ.
    Toro,
}

impl InformationOrder {
    /// The upper-triangle position of the `k`-th number as the file writes it.
    ///
    /// ```
    /// use posecov::input::graph::parse::InformationOrder;
    /// assert_eq!(InformationOrder::UpperTriangle.upper_index(3), 3);
    /// assert_eq!(InformationOrder::Toro.upper_index(3), 5); // θθ, upper-triangle index 5
    /// assert_eq!(InformationOrder::Toro.upper_index(4), 2); // xθ
    /// ```
    pub fn upper_index(self, k: usize) -> usize {
        const TORO: [usize; 6] = [0, 1, 3, 5, 2, 4];
        match self {
            Self::UpperTriangle => k,
            Self::Toro => TORO.get(k).copied().unwrap_or(k),
        }
    }
}

/// A tag posecov reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tag {
    /// As written in the file.
    pub name: &'static str,
    /// Vertex or edge.
    pub kind: Kind,
    /// Planar or spatial.
    pub dimension: Dimension,
    /// How an edge's information is written (vertices: unused).
    pub order: InformationOrder,
}

/// Every tag read, with its meaning.
pub const TAGS: &[Tag] = &[
    Tag {
        name: "VERTEX_SE2",
        kind: Kind::Vertex,
        dimension: Dimension::Planar,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "VERTEX2",
        kind: Kind::Vertex,
        dimension: Dimension::Planar,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "EDGE_SE2",
        kind: Kind::Edge,
        dimension: Dimension::Planar,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "EDGE2",
        kind: Kind::Edge,
        dimension: Dimension::Planar,
        order: InformationOrder::Toro,
    },
    Tag {
        name: "VERTEX_SE3:QUAT",
        kind: Kind::Vertex,
        dimension: Dimension::Spatial,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "EDGE_SE3:QUAT",
        kind: Kind::Edge,
        dimension: Dimension::Spatial,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "EDGE_PRIOR_SE2",
        kind: Kind::Prior,
        dimension: Dimension::Planar,
        order: InformationOrder::UpperTriangle,
    },
    Tag {
        name: "EDGE_SE3_PRIOR",
        kind: Kind::Prior,
        dimension: Dimension::Spatial,
        order: InformationOrder::UpperTriangle,
    },
];

/// g2o's `FIX id …` record (either dimension).
pub const FIX: Tag = Tag {
    name: "FIX",
    kind: Kind::Fix,
    dimension: Dimension::Planar,
    order: InformationOrder::UpperTriangle,
};

/// g2o records that are valid but not drawn: counted and skipped.
pub const SKIPPED_TAGS: &[&str] = &[
    "VERTEX_XY",
    "EDGE_SE2_XY",
    "EDGE_BEARING_SE2_XY",
    "VERTEX_TRACKXYZ",
    "EDGE_SE3_TRACKXYZ",
    "PARAMS_SE3OFFSET",
    "VERTEX3",
    "EDGE3",
    "VERTEX_SE3:EXPMAP",
    "VERTEX_SBA:POINT",
];

/// A number (or id) with its byte offset in the text.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Value {
    /// The number.
    pub value: f64,
    /// Byte offset of its token.
    pub at: usize,
}

/// A vertex id as a record writes it, with the byte offset of its token (where an error about
/// that vertex points).
///
/// ```
/// use posecov::input::Locator;
/// use posecov::input::graph::parse::{IdAt, read_records};
/// let r = read_records(&Locator::new("g.g2o", "VERTEX_SE2 7 0 0 0\n")).unwrap();
/// assert_eq!(r.records[0].ids, [IdAt { id: 7, at: 11 }]);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct IdAt {
    /// The vertex id.
    pub id: u64,
    /// Byte offset of its token.
    pub at: usize,
}

/// One record as read: tag, ids and numbers, located.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// Its tag.
    pub tag: Tag,
    /// 1-based line.
    pub line: usize,
    /// Byte offset of the tag.
    pub at: usize,
    /// The vertex id, or the edge's from and to ids, with their offsets.
    pub ids: Vec<IdAt>,
    /// The pose or measurement values (3 for SE(2), 7 for SE(3)).
    pub pose: Vec<Value>,
    /// The information matrix's upper triangle, row by row, whatever the file's order (edges
    /// only: 6 or 21), each value with its place in the file.
    pub information: Vec<Value>,
}

/// The names of the pose values of a dimension, in file order.
pub fn pose_names(dimension: Dimension) -> &'static [&'static str] {
    match dimension {
        Dimension::Planar => &["x", "y", "θ"],
        Dimension::Spatial => &["x", "y", "z", "qx", "qy", "qz", "qw"],
    }
}

/// The axes the information matrix is over, in file order.
pub fn information_axes(dimension: Dimension) -> &'static [&'static str] {
    match dimension {
        Dimension::Planar => &["x", "y", "θ"],
        Dimension::Spatial => &["x", "y", "z", "qx", "qy", "qz"],
    }
}

/// The whole file's records and what was skipped.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Records {
    /// Vertices and edges in file order.
    pub records: Vec<Record>,
    /// Skipped tags with their counts, in order of first appearance.
    pub skipped: Vec<SkippedRecords>,
}

/// Most records of one file (vertices + edges): larger graphs are refused before they are
/// drawn.
pub const MAX_RECORDS: usize = 1_000_000;

/// Splits `text` into records, checking tags, counts, ids and that every number is finite,
/// and that the file is all planar or all spatial.
///
/// ```
/// use posecov::input::Locator;
/// use posecov::input::graph::parse::read_records;
/// let text = "# comment\nVERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0.5 # trailing\n";
/// let r = read_records(&Locator::new("g.g2o", text)).unwrap();
/// assert_eq!(r.records.len(), 2);
/// assert_eq!(r.records[1].pose[2].value, 0.5);
/// let e = read_records(&Locator::new("g.g2o", "VERTEX_SE2 0 0 nan 0\n")).unwrap_err();
/// assert!(e.to_string().starts_with("g.g2o:1:16: VERTEX_SE2 0: y = nan is not a finite number"), "{e}");
/// ```
pub fn read_records(locator: &Locator) -> Result<Records, InputError> {
    let text = locator.text();
    let mut out = Records::default();
    let mut dimension: Option<(Dimension, usize)> = None;
    let mut offset = 0;
    let mut tokens = Vec::new();
    for (index, raw_line) in text.split_inclusive('\n').enumerate() {
        let line_start = offset;
        offset += raw_line.len();
        let content = raw_line.split('#').next().unwrap_or("");
        tokens_of(content, line_start, &mut tokens);
        let Some(&(tag_text, tag_at)) = tokens.first() else {
            continue;
        };
        let line = index + 1;
        if tag_text == FIX.name {
            out.records
                .push(fix_record(locator, line, tag_at, &tokens[1..])?);
            continue;
        }
        let Some(tag) = TAGS.iter().find(|t| t.name == tag_text).copied() else {
            if SKIPPED_TAGS.contains(&tag_text) {
                match out.skipped.iter_mut().find(|s| s.tag == tag_text) {
                    Some(s) => s.count += 1,
                    None => out.skipped.push(SkippedRecords {
                        tag: tag_text.to_owned(),
                        count: 1,
                    }),
                }
                continue;
            }
            let known: Vec<&str> = TAGS.iter().map(|t| t.name).collect();
            return Err(locator.error(
                tag_at..tag_at,
                "record",
                format!(
                    "`{tag_text}` is not a g2o record posecov reads (it reads {}; landmark and parameter records are skipped)",
                    known.join(", ")
                ),
            ));
        };
        match dimension {
            None => dimension = Some((tag.dimension, line)),
            Some((d, first)) if d != tag.dimension => {
                let what = |d| match d {
                    Dimension::Planar => "planar (SE(2))",
                    Dimension::Spatial => "3D (SE(3))",
                };
                return Err(locator.error(
                    tag_at..tag_at,
                    tag.name,
                    format!(
                        "a {} record in a {} graph (line {first} is {}); one file holds one kind of pose",
                        what(tag.dimension),
                        what(d),
                        what(d)
                    ),
                ));
            }
            _ => {}
        }
        if out.records.len() >= MAX_RECORDS {
            return Err(locator.error(
                tag_at..tag_at,
                tag.name,
                format!("more than {MAX_RECORDS} vertices and edges; posecov draws graphs up to that size"),
            ));
        }
        out.records
            .push(record(locator, tag, line, tag_at, &tokens[1..])?);
    }
    if out.records.is_empty() {
        let skipped = if out.skipped.is_empty() {
            String::new()
        } else {
            let s: Vec<String> = out
                .skipped
                .iter()
                .map(|s| format!("{} {}", s.count, s.tag))
                .collect();
            format!(" (only {})", s.join(", "))
        };
        return Err(locator.error(
            0..0,
            "file",
            format!(
                "no vertices or edges{skipped}: a pose graph needs VERTEX_SE2 / EDGE_SE2 or VERTEX_SE3:QUAT / EDGE_SE3:QUAT lines"
            ),
        ));
    }
    Ok(out)
}

/// The whitespace-separated tokens of `content` with their byte offsets in the whole text, in
/// `out` (emptied first: one buffer serves every line).
fn tokens_of<'a>(content: &'a str, line_start: usize, out: &mut Vec<(&'a str, usize)>) {
    out.clear();
    let mut start = None;
    for (i, c) in content.char_indices() {
        match (c.is_whitespace(), start) {
            (true, Some(s)) => {
                out.push((&content[s..i], line_start + s));
                start = None;
            }
            (false, None) => start = Some(i),
            _ => {}
        }
    }
    if let Some(s) = start {
        out.push((&content[s..], line_start + s));
    }
}

fn record(
    locator: &Locator,
    tag: Tag,
    line: usize,
    at: usize,
    values: &[(&str, usize)],
) -> Result<Record, InputError> {
    let id_count = match (tag.kind, tag.dimension) {
        (Kind::Edge, _) | (Kind::Prior, Dimension::Spatial) => 2,
        _ => 1,
    };
    let pose_names = pose_names(tag.dimension);
    let axes = information_axes(tag.dimension);
    let info_count = match tag.kind {
        Kind::Vertex | Kind::Fix => 0,
        Kind::Edge | Kind::Prior => axes.len() * (axes.len() + 1) / 2,
    };
    let expected = id_count + pose_names.len() + info_count;
    if values.len() != expected {
        let what = match tag.kind {
            Kind::Vertex | Kind::Fix => format!("id {}", pose_names.join(" ")),
            Kind::Prior => format!(
                "id{} {} and the {info_count} numbers of the information matrix's upper triangle",
                if id_count == 2 { " param" } else { "" },
                pose_names.join(" ")
            ),
            Kind::Edge => format!(
                "i j {} and the {info_count} numbers of the information matrix{}",
                pose_names.join(" "),
                match tag.order {
                    InformationOrder::UpperTriangle => "'s upper triangle",
                    InformationOrder::Toro => " in TORO's order: xx xy yy θθ xθ yθ",
                }
            ),
        };
        let place = values.get(expected).map_or(at, |v| v.1);
        return Err(locator.error(
            place..place,
            tag.name,
            format!(
                "expected {expected} values after the tag ({what}), found {}",
                values.len()
            ),
        ));
    }
    let mut ids = Vec::with_capacity(id_count);
    for (k, &(token, token_at)) in values[..id_count].iter().enumerate() {
        let name = match (tag.kind, k) {
            (Kind::Vertex | Kind::Fix, _) | (Kind::Prior, 0) => "id",
            (Kind::Prior, _) => "param (offset parameter id)",
            (_, 0) => "i (from)",
            _ => "j (to)",
        };
        let id = token.parse::<u64>().map_err(|_| {
            locator.error(
                token_at..token_at,
                tag.name,
                format!("{name} = `{token}` is not a vertex id (a whole number ≥ 0)"),
            )
        })?;
        ids.push(IdAt { id, at: token_at });
    }
    // The record's name in an error ("EDGE_SE3:QUAT 4 7"): written only for one.
    let label = || {
        let ids: Vec<String> = ids.iter().map(|i| i.id.to_string()).collect();
        format!("{} {}", tag.name, ids.join(" "))
    };
    // `name` is written only for an error (an edge has 21 numbers of the information).
    let number = |(token, token_at): (&str, usize),
                  name: &dyn Fn() -> String|
     -> Result<Value, InputError> {
        match token.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Value {
                value: v,
                at: token_at,
            }),
            Ok(_) => Err(locator.error(
                token_at..token_at,
                &label(),
                format!("{} = {token} is not a finite number", name()),
            )),
            Err(_) => Err(locator.error(
                token_at..token_at,
                &label(),
                format!("{} = `{token}` is not a number", name()),
            )),
        }
    };
    let pose = values[id_count..id_count + pose_names.len()]
        .iter()
        .zip(pose_names)
        .map(|(t, name)| number(*t, &|| (*name).to_owned()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut information = vec![Value { value: 0.0, at }; info_count];
    for (k, t) in values[id_count + pose_names.len()..].iter().enumerate() {
        let upper = tag.order.upper_index(k);
        information[upper] = number(*t, &|| super::convention::upper_triangle_name(axes, upper))?;
    }
    Ok(Record {
        tag,
        line,
        at,
        ids,
        pose,
        information,
    })
}

/// `FIX id …`: one or more vertex ids.
fn fix_record(
    locator: &Locator,
    line: usize,
    at: usize,
    values: &[(&str, usize)],
) -> Result<Record, InputError> {
    if values.is_empty() {
        return Err(locator.error(
            at..at,
            FIX.name,
            "expected the ids of the vertices to hold fixed after FIX, found none",
        ));
    }
    let mut ids = Vec::with_capacity(values.len());
    for &(token, token_at) in values {
        let id = token.parse::<u64>().map_err(|_| {
            locator.error(
                token_at..token_at,
                FIX.name,
                format!("id = `{token}` is not a vertex id (a whole number ≥ 0)"),
            )
        })?;
        ids.push(IdAt { id, at: token_at });
    }
    Ok(Record {
        tag: FIX,
        line,
        at,
        ids,
        pose: Vec::new(),
        information: Vec::new(),
    })
}
