//! Scenes as share links: the part after `#` of
//! `index.html#formula=x%5E2…&angles=a,b,c,d,e,f&domain=x0,x1,y0,y1,z0,z1,w0,w1&R=0.5`.
//!
//! A link holds the formula, then only what differs from a scene with default settings:
//! `angles`, `zoom`, `pan`, `slab`, `slice` (the view), `domain` (eight numbers), each
//! parameter by its name, and any other scene key by its path in the scene file
//! (`render.rays=4`, `tree.max_level=7`, `render.lighting.ambient=0.3`). Keys left out take
//! their defaults. Numbers are written to 7 significant digits. A key whose value is wrong
//! is left out and reported, so the rest of the link still opens; the formula is kept as
//! typed (the editor shows its error).

use percent_encoding::{AsciiSet, NON_ALPHANUMERIC, percent_decode_str, utf8_percent_encode};
use toml::{Table, Value};

use super::keys::{Speaker, TABLES, VIEW_KEYS, link_key};
use super::limits::LINK_KEYS;
use super::settings::{Domain, Scene};

/// Bytes written as they are in a link; everything else is percent-encoded (`+`, `&`, `=`,
/// `#`, `%` and spaces among them).
const KEPT: &AsciiSet = &NON_ALPHANUMERIC
    .remove(b'-')
    .remove(b'.')
    .remove(b'_')
    .remove(b'~')
    .remove(b',')
    .remove(b'(')
    .remove(b')')
    .remove(b'*')
    .remove(b'/');

/// One key of a link that was left out, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct LinkProblem {
    pub key: String,
    pub message: String,
}

impl std::fmt::Display for LinkProblem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "in the link, {}: {}", self.key, self.message)
    }
}

/// Whether `text` looks like a share link rather than a formula or a path: it has a `#`
/// followed by `key=value`, or starts with `formula=`.
pub fn is_link(text: &str) -> bool {
    let fragment = text.split_once('#').map_or(text, |(_, f)| f);
    (text.contains('#') && fragment.contains('=')) || text.trim_start().starts_with("formula=")
}

impl Scene {
    /// The share link's fragment (without `#`) of this scene.
    pub fn to_link(&self) -> String {
        let scene = Value::try_from(self).expect("a scene always serialises");
        let defaults =
            Value::try_from(Scene::from_formula(&self.formula)).expect("a scene always serialises");
        let (mut here, mut base) = (Vec::new(), Vec::new());
        flatten("", &scene, &mut here);
        flatten("", &defaults, &mut base);
        let mut parts = vec![format!("formula={}", encode(&self.formula))];
        let axes = ["domain.x", "domain.y", "domain.z", "domain.w"];
        if here.iter().any(|(k, v)| {
            axes.contains(&k.as_str())
                && base.iter().find(|(b, _)| b == k).map(|(_, d)| d) != Some(v)
        }) {
            let list: Vec<String> = self
                .domain
                .axes()
                .iter()
                .flat_map(|a| [number(a.lo), number(a.hi)])
                .collect();
            parts.push(format!("domain={}", list.join(",")));
        }
        for (key, value) in &here {
            let unchanged = base.iter().any(|(k, v)| k == key && v == value);
            if unchanged || key == "formula" || axes.contains(&key.as_str()) {
                continue;
            }
            parts.push(format!("{}={}", link_key(key), encode(&text_of(value))));
        }
        parts.join("&")
    }

    /// The scene of a share link (a whole address, or only what follows `#`). Keys that
    /// are wrong are left at their defaults and listed. Without a formula, the link changes
    /// `fallback`.
    pub fn from_link(link: &str, fallback: &Scene) -> (Scene, Vec<LinkProblem>) {
        let fragment = link.split_once('#').map_or(link, |(_, f)| f).trim();
        let mut pairs = Vec::new();
        let mut problems = Vec::new();
        for part in fragment.split('&').filter(|p| !p.is_empty()) {
            let (key, value) = part.split_once('=').unwrap_or((part, ""));
            match (decode(key), decode(value)) {
                (Ok(key), Ok(value)) => pairs.push((key, value)),
                (Err(e), _) | (_, Err(e)) => problems.push(LinkProblem {
                    key: key.to_string(),
                    message: e,
                }),
            }
        }
        let formula = pairs.iter().find(|(k, _)| k == "formula").map(|(_, v)| v);
        let start = match formula {
            Some(f) => Scene::from_formula(f),
            None => fallback.clone(),
        };
        let mut table = match Value::try_from(&start) {
            Ok(Value::Table(t)) => t,
            _ => unreachable!("a scene serialises to a table"),
        };
        let mut keys: Vec<&(String, String)> =
            pairs.iter().filter(|(k, _)| k != "formula").collect();
        if keys.len() > LINK_KEYS {
            problems.push(LinkProblem {
                key: keys[LINK_KEYS].0.clone(),
                message: format!(
                    "a link holds at most {LINK_KEYS} keys: this one and the {} after it are \
                     left out",
                    keys.len() - LINK_KEYS - 1
                ),
            });
            keys.truncate(LINK_KEYS);
        }
        // Most links are whole: every key at once, checked once.
        let mut whole = table.clone();
        if keys.iter().all(|(k, v)| apply(&mut whole, k, v).is_ok()) && checked(&whole).is_ok() {
            table = whole;
        } else {
            problems.extend(apply_each(&mut table, keys));
        }
        let scene = Value::Table(table)
            .try_into()
            .expect("every key kept was checked with the ones before it");
        (scene, problems)
    }
}

/// Applies the keys one by one, each kept only if the scene it makes is one the rules
/// accept; the problems of those left out. A key that breaks a rule with another
/// (tree.max_level below the default tree.min_level, before the link's own min_level) is
/// tried again after the rest; such rules pair two keys, so a few rounds settle every link.
fn apply_each(table: &mut Table, keys: Vec<&(String, String)>) -> Vec<LinkProblem> {
    let mut pending = keys;
    for round in 1..=3 {
        let mut refused = Vec::new();
        for &pair in &pending {
            let mut tried = table.clone();
            match apply(&mut tried, &pair.0, &pair.1).and_then(|()| checked(&tried)) {
                Ok(()) => *table = tried,
                Err(message) => refused.push((pair, message)),
            }
        }
        if refused.len() == pending.len() || round == 3 {
            return refused
                .into_iter()
                .map(|((key, _), message)| LinkProblem {
                    key: key.clone(),
                    message,
                })
                .collect();
        }
        pending = refused.into_iter().map(|(pair, _)| pair).collect();
    }
    unreachable!("the last round returns")
}

/// Whether a scene's table makes a scene the rules accept; the first problem if not.
fn checked(table: &Table) -> Result<(), String> {
    let scene: Scene = Value::Table(table.clone())
        .try_into()
        .map_err(|e: toml::de::Error| e.message().to_string())?;
    scene
        .check()
        .map_err(|invalid| invalid.message(Speaker::Link))
}

/// A name the formula language reads as a parameter: a letter or `_`, then letters, digits
/// and `_`.
fn is_parameter_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// Sets `key` (as a link spells it) to `text` in a scene's table.
fn apply(table: &mut Table, key: &str, text: &str) -> Result<(), String> {
    if key == "domain" {
        let domain = Domain::parse_list(text)?;
        let value = Value::try_from(domain).map_err(|e| e.to_string())?;
        table.insert("domain".into(), value);
        return Ok(());
    }
    let path: Vec<&str> = if key == "description" {
        vec!["description"]
    } else if VIEW_KEYS.contains(&key) {
        vec!["view", key]
    } else if key.contains('.') {
        key.split('.').collect()
    } else {
        vec!["params", key]
    };
    if path[0] == "params" {
        let name = path[1..].join(".");
        if !is_parameter_name(&name) {
            return Err(format!(
                "`{name}` is neither a link key nor a parameter name (link keys: formula, \
                 angles, zoom, pan, slab, slice, domain, and scene keys such as render.rays)"
            ));
        }
    } else if path.len() > 1 && !TABLES.contains(&path[0]) {
        return Err(format!(
            "unknown table `{}` (the scene's tables are {})",
            path[0],
            TABLES.join(", ")
        ));
    }
    let value = if key == "description" {
        Value::String(text.to_string())
    } else {
        value_of(text)
    };
    let (last, tables) = path.split_last().expect("a key has a name");
    let mut here = table;
    for name in tables {
        here = match here
            .entry(name.to_string())
            .or_insert_with(|| Value::Table(Table::new()))
        {
            Value::Table(t) => t,
            _ => return Err(format!("`{name}` is not a table")),
        };
    }
    here.insert(last.to_string(), value);
    Ok(())
}

/// A link value as TOML: a number, `true`/`false`, a comma list (an array), else a string.
fn value_of(text: &str) -> Value {
    let literal = if text.contains(',') && !text.starts_with('[') {
        format!("v = [{text}]")
    } else {
        format!("v = {text}")
    };
    match literal
        .parse::<Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
    {
        Some(v) => v,
        None => Value::String(text.to_string()),
    }
}

/// A value as a link writes it.
fn text_of(value: &Value) -> String {
    match value {
        Value::String(s) => s.clone(),
        Value::Float(f) => number(*f),
        Value::Array(items) => items.iter().map(text_of).collect::<Vec<_>>().join(","),
        other => other.to_string(),
    }
}

/// `x` to 7 significant digits, as short as it goes: a turn by the mouse leaves angles
/// like 0.20225399386234777, and a millionth of a radian or of a zoom changes no pixel.
fn number(x: f64) -> String {
    let rounded: f64 = format!("{x:.6e}").parse().unwrap_or(x);
    let (plain, exponent) = (format!("{rounded}"), format!("{rounded:e}"));
    if exponent.len() < plain.len() {
        exponent
    } else {
        plain
    }
}

/// Every leaf of a TOML value with its dotted path.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<(String, Value)>) {
    match value {
        Value::Table(table) => {
            for (key, v) in table {
                let path = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                flatten(&path, v, out);
            }
        }
        _ => out.push((prefix.to_string(), value.clone())),
    }
}

fn encode(text: &str) -> String {
    utf8_percent_encode(text, KEPT).to_string()
}

fn decode(text: &str) -> Result<String, String> {
    percent_decode_str(text)
        .decode_utf8()
        .map(|s| s.into_owned())
        .map_err(|_| "the %-escapes here are not UTF-8 text".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_example_survives_the_round_trip() {
        for (name, _) in crate::scene::EXAMPLES {
            let scene = Scene::example(name).unwrap();
            let link = scene.to_link();
            let (back, problems) =
                Scene::from_link(&format!("index.html#{link}"), &Scene::from_formula("0"));
            assert!(problems.is_empty(), "{name}: {problems:?}");
            assert_eq!(back.to_toml(), scene.to_toml(), "{name}: {link}");
        }
    }

    #[test]
    fn a_changed_scene_keeps_its_changes() {
        let mut scene = Scene::from_formula("x^2 + y^2 + z^2 + w^2 - R & 1");
        scene.params.insert("R".into(), 0.25);
        scene.view.angles = [0.1, -0.2, 0.3, 1e-9, 0.0, 3.0];
        scene.view.slice = Some(-0.5);
        scene.render.rays = 4;
        scene.render.lighting.ambient = 0.3;
        scene.render.background = crate::scene::Color([1, 2, 255]);
        scene.tree.max_level = 7;
        scene.domain = crate::scene::Domain::parse_list("-2,2,-1,1,-1,1,0,1").unwrap();
        let link = scene.to_link();
        assert!(link.starts_with("formula=x%5E2%20%2B"), "{link}");
        assert!(link.contains("&R=0.25"), "{link}");
        assert!(link.contains("&domain=-2,2,-1,1,-1,1,0,1"), "{link}");
        let (back, problems) = Scene::from_link(&link, &Scene::from_formula("0"));
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(back.to_toml(), scene.to_toml());
    }

    #[test]
    fn keys_that_depend_on_each_other_open_in_any_order() {
        // max_level 3 is below the default min_level 4 until the link's min_level comes.
        let mut scene = Scene::from_formula("x + y");
        scene.tree.max_level = 3;
        scene.tree.min_level = 2;
        let (back, problems) = Scene::from_link(&scene.to_link(), &Scene::from_formula("0"));
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(back.tree, scene.tree);
        let reversed = "formula=x&tree.min_level=9&tree.max_level=9";
        let (back, problems) = Scene::from_link(reversed, &Scene::from_formula("0"));
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!((back.tree.min_level, back.tree.max_level), (9, 9));
        // A pair no order can settle is refused, and the scene stays one the rules accept.
        let (back, problems) =
            Scene::from_link("formula=x&tree.min_level=8&tree.max_level=2", &back);
        assert_eq!(problems.len(), 2, "{problems:?}");
        assert!(back.check().is_ok());
    }

    #[test]
    fn keys_left_out_take_their_defaults() {
        let (scene, problems) = Scene::from_link(
            "#formula=x%2By&angles=1,2,3,4,5,6",
            &Scene::from_formula("0"),
        );
        assert!(problems.is_empty());
        assert_eq!(scene.formula, "x+y");
        assert_eq!(scene.view.angles, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(scene.render, Scene::from_formula("x").render);
        let fallback = Scene::example("glome").unwrap();
        let (scene, _) = Scene::from_link("#zoom=2", &fallback);
        assert_eq!(
            (scene.formula.as_str(), scene.view.zoom),
            (fallback.formula.as_str(), 2.0)
        );
    }

    #[test]
    fn wrong_keys_are_reported_and_the_rest_opens() {
        let link = "https://example.org/fourfold/#formula=x^2%20-%20(&angles=1,2,3&render.rays=0\
                    &domain=1,0,0,1,0,1,0,1&zoom=3&render.raysx=2&colour.x=1&a-b=2&R=%FF";
        let (scene, problems) = Scene::from_link(link, &Scene::from_formula("0"));
        // The formula is kept as typed: the editor shows where it is wrong.
        assert_eq!(scene.formula, "x^2 - (");
        assert_eq!(scene.view.zoom, 3.0);
        let keys: Vec<&str> = problems.iter().map(|p| p.key.as_str()).collect();
        assert_eq!(
            keys,
            [
                "R",
                "angles",
                "render.rays",
                "domain",
                "render.raysx",
                "colour.x",
                "a-b"
            ]
        );
        let said: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
        assert!(said[1].contains("6"), "{}", said[1]);
        assert!(said[2].contains("between 1 and"), "{}", said[2]);
        assert!(said[3].contains("axis x"), "{}", said[3]);
        assert!(said[4].contains("unknown field"), "{}", said[4]);
        assert!(said[5].contains("unknown table"), "{}", said[5]);
        assert!(
            said[6].contains("neither a link key nor a parameter"),
            "{}",
            said[6]
        );
    }

    #[test]
    fn a_link_with_too_many_keys_keeps_the_first_ones_and_says_so() {
        // Ten thousand parameters, one of them wrong: before, each key was checked against
        // all those before it (quadratic, minutes for a link anyone can send).
        let mut link = String::from("formula=x-a0");
        for i in 0..10_000 {
            link.push_str(&format!("&a{i}={}", if i == 7 { "nan" } else { "0.5" }));
        }
        let (scene, problems) = Scene::from_link(&link, &Scene::from_formula("0"));
        assert_eq!(scene.params.len(), LINK_KEYS - 1);
        assert_eq!((scene.params["a0"], scene.params.get("a7")), (0.5, None));
        let said: Vec<String> = problems.iter().map(|p| p.to_string()).collect();
        assert_eq!(said.len(), 2, "{said:?}");
        assert!(said[0].contains("at most 256 keys"), "{}", said[0]);
        assert!(said[0].starts_with("in the link, a256:"), "{}", said[0]);
        assert!(said[0].contains("the 9743 after it"), "{}", said[0]);
        assert!(said[1].starts_with("in the link, a7:"), "{}", said[1]);
    }

    #[test]
    fn numbers_are_written_to_seven_digits() {
        let mut scene = Scene::from_formula("x");
        scene.view.angles = [0.20225399386234777, -1e-12, 3.0, 0.0, 0.0, 0.0];
        scene.view.zoom = 1.6635705050219636;
        let link = scene.to_link();
        assert!(link.contains("angles=0.202254,-1e-12,3,0,0,0"), "{link}");
        assert!(link.contains("zoom=1.663571"), "{link}");
    }

    #[test]
    fn a_parameter_named_like_a_key_keeps_its_table() {
        let mut scene = Scene::from_formula("x - zoom");
        scene.params.insert("zoom".into(), 0.5);
        let link = scene.to_link();
        assert!(link.contains("params.zoom=0.5"), "{link}");
        let (back, problems) = Scene::from_link(&link, &Scene::from_formula("0"));
        assert!(problems.is_empty());
        assert_eq!((back.params["zoom"], back.view.zoom), (0.5, 1.0));
    }

    #[test]
    fn links_are_told_from_formulas_and_paths() {
        assert!(is_link("index.html#formula=x"));
        assert!(is_link("https://a.b/#formula=x&zoom=2"));
        assert!(is_link("formula=x"));
        assert!(!is_link("x^2 + y^2 - 1"));
        assert!(!is_link("scenes/glome.toml"));
    }
}
