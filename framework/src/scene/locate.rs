//! Finds the line of a key path (`bodies[3].radius`) in a TOML text, for messages.

use toml_edit::{Item, Table, Value};

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
            (Seg::Key(k), Node::Item(it)) => it.as_table_like().and_then(|t| t.get_key_value(k)).map(|(key, it)| (key.span(), Node::Item(it))),
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

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn finds_lines() {
        let text = "a = 1\n[[bodies]]\nx = 1\n\n[[bodies]]\nradius = -1\n[time]\nstep = 2\n";
        let line = |p: &[Seg]| locate(text, p).map(|o| crate::error::line_of(text, o));
        assert_eq!(line(&[Seg::Key("bodies".into()), Seg::Index(1), Seg::Key("radius".into())]), Some(6));
        assert_eq!(line(&[Seg::Key("time".into()), Seg::Key("step".into())]), Some(8));
        assert_eq!(line(&[Seg::Key("bodies".into()), Seg::Index(1), Seg::Key("nothing".into())]), Some(5));
    }
}
