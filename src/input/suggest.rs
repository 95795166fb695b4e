//! "Did you mean …?": the nearest of the names a place accepts, for a name that is none of
//! them (a bundled example, a key, a method, an operation kind, a pose, a topic).
//!
//! Nearness is the Jaro–Winkler similarity (`strsim`, as clap suggests flags): above 0.8,
//! the most similar wins; nothing is suggested when no name is that close.

/// The accepted name nearest to `word`, if one is near enough.
///
/// ```
/// use posecov::input::suggest::nearest;
/// assert_eq!(nearest("camera_on_robt", ["camera_on_robot", "so3_sampling"]), Some("camera_on_robot"));
/// assert_eq!(nearest("xyz", ["camera_on_robot"]), None);
/// ```
pub fn nearest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    candidates
        .into_iter()
        .filter(|c| *c != word)
        .map(|c| (strsim::jaro_winkler(word, c), c))
        .filter(|(similarity, _)| *similarity > 0.8)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| c)
}

/// `"did you mean `x`? "` for the nearest accepted name, or nothing.
///
/// ```
/// use posecov::input::suggest::did_you_mean;
/// assert_eq!(did_you_mean("first_ordr", ["first_order", "monte_carlo"]), "did you mean `first_order`? ");
/// assert_eq!(did_you_mean("zzz", ["first_order"]), "");
/// ```
pub fn did_you_mean<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    nearest(word, candidates).map_or_else(String::new, |c| format!("did you mean `{c}`? "))
}
