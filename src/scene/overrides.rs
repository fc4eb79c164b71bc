//! `--set key=value` overrides: a dotted key (`section.key`, `shapes[0].key`)
//! or a bare name searched in a few sections, its value parsed as TOML, applied
//! to the scene's table before it is deserialised.

use crate::error::InputError;

/// The scene's sections that `--set 'name={ ... }'` gives whole, present or not
/// (SceneFile's table fields).
const SECTIONS: [&str; 9] = [
    "run",
    "check",
    "watchdog",
    "laser",
    "scan",
    "surface_tension",
    "powder",
    "contact",
    "heat",
];

/// Sections searched, in order, for a bare `--set name=value`.
const ALIAS_SECTIONS: [&str; 4] = ["simulation", "run", "domain", "check"];

pub(super) fn apply_override(
    file: &str,
    table: &mut toml::Table,
    ov: &str,
) -> Result<(), InputError> {
    let Some((key, raw)) = ov.split_once('=') else {
        return Err(InputError::new(file, ov, "--set expects key=value"));
    };
    let key = key.trim();
    let value = parse_value(raw.trim());
    let path: Vec<String> = if key.contains('.') {
        key.split('.').map(str::to_string).collect()
    } else if value.is_table()
        && (table.get(key).is_some_and(toml::Value::is_table) || SECTIONS.contains(&key))
    {
        // A whole section: `--set 'check={ kind = "compression", tolerance = 0.02 }'`.
        vec![key.to_string()]
    } else {
        let hits: Vec<&str> = ALIAS_SECTIONS
            .iter()
            .copied()
            .filter(|s| {
                table
                    .get(*s)
                    .and_then(|t| t.as_table())
                    .is_some_and(|t| t.contains_key(key))
            })
            .collect();
        match hits.as_slice() {
            [one] => vec![one.to_string(), key.to_string()],
            [] => {
                // Not present yet: an optional key of [run] or [simulation].
                let section = if RUN_KEYS.contains(&key) {
                    "run"
                } else {
                    "simulation"
                };
                vec![section.to_string(), key.to_string()]
            }
            _ => {
                return Err(InputError::new(
                    file,
                    key,
                    format!(
                        "--set: ambiguous key, found in sections {}; write section.key",
                        hits.join(", ")
                    ),
                ))
            }
        }
    };
    for (k, seg) in path.iter().enumerate() {
        let bracket = seg.contains(['[', ']']);
        if bracket && (indexed(seg).is_none() || k + 1 == path.len()) {
            return Err(InputError::new(
                file,
                key,
                format!(
                    "--set: `{seg}`: an array-of-tables entry is written name[k] with k a whole \
                     number from 0, followed by a key (shapes[0].velocity=[0.0, 0.0, -1.0])"
                ),
            ));
        }
    }
    let mut node = table;
    for seg in &path[..path.len() - 1] {
        node = match indexed(seg) {
            Some((name, k)) => array_entry(file, key, node, name, k)?,
            None => node
                .entry(seg.clone())
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
                .ok_or_else(|| {
                    InputError::new(file, key, format!("--set: `{seg}` is not a table"))
                })?,
        };
    }
    node.insert(path[path.len() - 1].clone(), value);
    Ok(())
}

/// `name[k]` in a `--set` path: an entry of an array of tables
/// (`shapes[0].velocity=[0, 0, -10]`).
fn indexed(seg: &str) -> Option<(&str, usize)> {
    let (name, rest) = seg.split_once('[')?;
    let k = rest.strip_suffix(']')?.trim();
    // Digits only: usize's parser would take "+1".
    if name.is_empty() || !k.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    Some((name, k.parse().ok()?))
}

/// Table `k` of the array of tables `name` in `node`; a missing array or an
/// index past its end is an error naming the key.
fn array_entry<'a>(
    file: &str,
    key: &str,
    node: &'a mut toml::Table,
    name: &str,
    k: usize,
) -> Result<&'a mut toml::Table, InputError> {
    let err = |why: String| InputError::new(file, key, format!("--set: {why}"));
    let array = node
        .get_mut(name)
        .and_then(|v| v.as_array_mut())
        .ok_or_else(|| err(format!("the scene has no [[{name}]] entries")))?;
    let n = array.len();
    array
        .get_mut(k)
        .ok_or_else(|| {
            let entries = if n == 1 { "entry" } else { "entries" };
            err(format!(
                "index {k} is past the {n} [[{name}]] {entries} (indices from 0)"
            ))
        })?
        .as_table_mut()
        .ok_or_else(|| err(format!("`{name}[{k}]` is not a table")))
}

/// Every key of `[run]` (RunDef's fields): a bare `--set` name not yet in the
/// file goes to `[run]` when it is one of these, else to `[simulation]`.
const RUN_KEYS: [&str; 9] = [
    "end_time",
    "steps",
    "dt",
    "max_dt",
    "output_interval",
    "diagnostics_interval",
    "dt_check",
    "stop_when",
    "stop_grace",
];

fn parse_value(raw: &str) -> toml::Value {
    let doc = format!("v = {raw}");
    match doc.parse::<toml::Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or(toml::Value::String(raw.to_string())),
        Err(_) => toml::Value::String(raw.to_string()),
    }
}

#[cfg(test)]
mod tests {
    /// RUN_KEYS names every field of RunDef (serde's refusal of an unknown key
    /// lists them): a bare `--set max_dt=…` once went to `[simulation]` and
    /// exited 2.
    #[test]
    fn run_keys_are_every_field_of_run() {
        let err = toml::from_str::<crate::scene::RunDef>("not_a_key = 1")
            .unwrap_err()
            .to_string();
        let listed = err.split("expected one of").nth(1).expect(&err);
        let mut fields: Vec<&str> = listed.split('`').skip(1).step_by(2).collect();
        let mut keys = super::RUN_KEYS.to_vec();
        fields.sort_unstable();
        keys.sort_unstable();
        assert_eq!(fields, keys);
    }
}
