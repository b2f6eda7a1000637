//! Finds the line of a key path (`bodies[3].radius`) in a TOML text, for messages.

use toml_edit::{Item, Table, TableLike, Value};

/// One step of a key path.
#[derive(Clone, Debug, PartialEq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// Formats a path as `a.b[2].c`.
pub fn path_string(path: &[Seg]) -> String {
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

enum Node<'a> {
    Item(&'a Item),
    Table(&'a Table),
    Value(&'a Value),
}

/// Byte span of the deepest part of `path` found in `text`.
pub fn locate(text: &str, path: &[Seg]) -> Option<usize> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let mut node = Node::Table(doc.as_table());
    let mut best: Option<usize> = None;
    for seg in path {
        let next = match (seg, &node) {
            (Seg::Key(k), Node::Table(t)) => t.get_key_value(k).map(|(key, it)| (key.span(), Node::Item(it))),
            (Seg::Key(k), Node::Item(it)) => it
                .as_table_like()
                .and_then(|t| t.get_key_value(k))
                .map(|(key, it)| (key.span(), Node::Item(it))),
            (Seg::Key(k), Node::Value(Value::InlineTable(t))) => t.get_key_value(k).map(|(key, it)| (key.span(), Node::Item(it))),
            (Seg::Index(i), Node::Item(Item::ArrayOfTables(a))) => a.get(*i).map(|t| (t.span(), Node::Table(t))),
            (Seg::Index(i), Node::Item(Item::Value(Value::Array(a)))) | (Seg::Index(i), Node::Value(Value::Array(a))) => {
                a.get(*i).map(|v| (v.span(), Node::Value(v)))
            }
            _ => None,
        };
        match next {
            Some((span, n)) => {
                if let Some(sp) = span {
                    best = Some(sp.start);
                }
                node = n;
            }
            None => break,
        }
    }
    best
}

/// Key path (`bodies[1].drive.z`) of the deepest key or value whose text holds the
/// byte `offset`, in a text that parses as TOML (for the deserializer's messages).
pub fn path_at(text: &str, offset: usize) -> Option<String> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let mut w = Walk {
        offset,
        path: vec![],
        best: None,
    };
    w.table(doc.as_table());
    w.best.map(|p| path_string(&p))
}

struct Walk {
    offset: usize,
    path: Vec<Seg>,
    best: Option<Vec<Seg>>,
}

impl Walk {
    fn hit(&mut self, span: Option<std::ops::Range<usize>>) {
        if span.is_some_and(|s| s.contains(&self.offset)) {
            self.best = Some(self.path.clone());
        }
    }
    fn table(&mut self, t: &dyn TableLike) {
        for (name, _) in t.iter() {
            let Some((key, item)) = t.get_key_value(name) else { continue };
            self.path.push(Seg::Key(name.to_string()));
            self.hit(key.span());
            self.hit(item.span());
            self.item(item);
            self.path.pop();
        }
    }
    fn item(&mut self, it: &Item) {
        match it {
            Item::Table(t) => self.table(t),
            Item::ArrayOfTables(a) => {
                for (i, t) in a.iter().enumerate() {
                    self.path.push(Seg::Index(i));
                    self.hit(t.span());
                    self.table(t);
                    self.path.pop();
                }
            }
            Item::Value(v) => self.value(v),
            Item::None => {}
        }
    }
    fn value(&mut self, v: &Value) {
        match v {
            Value::InlineTable(t) => self.table(t),
            Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    self.path.push(Seg::Index(i));
                    self.hit(x.span());
                    self.value(x);
                    self.path.pop();
                }
            }
            _ => {}
        }
    }
}

/// Best-effort key path of line `line` (1-based) in a text that does not parse:
/// the last table header above it (arrays of tables counted) and the key that
/// starts the line, e.g. `materials[0].name`.
pub fn path_on_line(text: &str, line: usize) -> Option<String> {
    let mut table = String::new();
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    for (i, l) in text.lines().enumerate().take(line) {
        let s = l.trim();
        if i + 1 == line {
            if s.starts_with('[') {
                return None;
            }
            let key = s.split('=').next()?.split_whitespace().next()?;
            if key.is_empty() || !key.chars().all(|c| c.is_alphanumeric() || "_-.\"".contains(c)) {
                return None;
            }
            return Some(if table.is_empty() {
                key.to_string()
            } else {
                format!("{table}.{key}")
            });
        }
        if let Some((h, _)) = s.strip_prefix("[[").and_then(|r| r.split_once("]]")) {
            let h = h.trim().to_string();
            let c = counts.entry(h.clone()).or_insert(0);
            table = format!("{h}[{c}]");
            *c += 1;
        } else if let Some((h, _)) = s.strip_prefix('[').and_then(|r| r.split_once(']')) {
            table = h.trim().to_string();
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn finds_lines() {
        let text = "a = 1\n[[bodies]]\nx = 1\n\n[[bodies]]\nradius = -1\n[time]\nstep = 2\n";
        let line = |p: &[Seg]| locate(text, p).map(|o| crate::error::line_of(text, o));
        assert_eq!(
            line(&[Seg::Key("bodies".into()), Seg::Index(1), Seg::Key("radius".into())]),
            Some(6)
        );
        assert_eq!(line(&[Seg::Key("time".into()), Seg::Key("step".into())]), Some(8));
        assert_eq!(
            line(&[Seg::Key("bodies".into()), Seg::Index(1), Seg::Key("nothing".into())]),
            Some(5)
        );
    }

    #[test]
    fn paths_of_offsets() {
        let text = "[time]\nstep = 1\n[[bodies]]\nr = 1\n[[bodies]]\ndrive.z = { v = 1 }\n";
        let at = |needle: &str| path_at(text, text.find(needle).unwrap());
        assert_eq!(at("step").as_deref(), Some("time.step"));
        assert_eq!(at("z =").as_deref(), Some("bodies[1].drive.z"));
        assert_eq!(at("v =").as_deref(), Some("bodies[1].drive.z.v"));
        let bad = "[[m]]\nname = 1\n[[m]]\nname = \"a\" x\n";
        assert_eq!(path_on_line(bad, 4).as_deref(), Some("m[1].name"));
        assert_eq!(path_on_line("a = 1 2\n", 1).as_deref(), Some("a"));
    }
}
