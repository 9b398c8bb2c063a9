//! How each reader of a scene names its keys: the scene file by the key (at its line), the
//! command line by the flag that sets it, a share link by the key it spells.

/// How a problem is told: by scene-file key, by command-line flag, by share-link key or by
/// the Python package's keyword argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speaker {
    File,
    Flag,
    Link,
    Keyword,
}

/// The command-line flag that sets the scene key `key` (its last part, dashed).
pub fn flag_of(key: &str) -> String {
    if let Some(name) = key.strip_prefix("params.") {
        return format!("--param {name}");
    }
    let last = key.rsplit('.').next().unwrap_or(key);
    format!("--{}", last.replace('_', "-"))
}

/// The Python keyword argument that sets the scene key `key`: its last part (`rays`,
/// `max_level`), a parameter as `params['R']`, a domain axis as `domain`.
pub fn keyword_of(key: &str) -> String {
    if let Some(name) = key.strip_prefix("params.") {
        return format!("params['{name}']");
    }
    if key.starts_with("domain.") {
        return "domain".to_string();
    }
    key.rsplit('.').next().unwrap_or(key).to_string()
}

/// The key a link spells for the scene file's `path`.
pub fn link_key(path: &str) -> String {
    if let Some(name) = path.strip_prefix("params.") {
        // A parameter named like a link key keeps its table, so it reads back as a parameter.
        return if is_reserved(name) {
            path.to_string()
        } else {
            name.to_string()
        };
    }
    match path.strip_prefix("view.") {
        Some(key) if VIEW_KEYS.contains(&key) => key.to_string(),
        _ => path.to_string(),
    }
}

/// The view's keys, written without their `view.` table.
pub(super) const VIEW_KEYS: [&str; 5] = ["angles", "zoom", "pan", "slab", "slice"];

/// Tables of the scene file whose keys a link spells with a dot.
pub(super) const TABLES: [&str; 4] = ["domain", "view", "tree", "render"];

pub(super) fn is_reserved(name: &str) -> bool {
    name == "formula"
        || name == "description"
        || VIEW_KEYS.contains(&name)
        || TABLES.contains(&name)
}

/// The span of the line that sets `key` (a dotted path) in scene text, for problems found
/// after parsing: the key within its table (`[render.border]`, then `tolerance`), or the
/// table's header; 0..0 where the text does not set it.
pub fn locate(text: &str, key: &str) -> std::ops::Range<usize> {
    let (table, leaf) = key.rsplit_once('.').unwrap_or(("", key));
    let mut section = String::new();
    let mut header = None;
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let start = offset + (line.len() - trimmed.len());
        let span = start..offset + line.trim_end().len();
        offset += line.len();
        if let Some(name) = trimmed.strip_prefix('[') {
            section = name.split(']').next().unwrap_or("").trim().to_string();
            if section == key || (section == table && header.is_none()) {
                header = Some(span.clone());
            }
            continue;
        }
        let sets_leaf = trimmed
            .strip_prefix(leaf)
            .is_some_and(|rest| rest.trim_start().starts_with('='));
        if section == table && sets_leaf {
            return span;
        }
    }
    header.unwrap_or(0..0)
}
