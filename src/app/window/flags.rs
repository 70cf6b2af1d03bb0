//! The viewer's switches as command-line flags: one source of truth with `run`. A flip
//! edits the argument list and parses it with `run`'s own parser, so a control has the
//! flag's name, accepts exactly its values, and the list is the `fluidform run` command
//! line to copy.
use crate::config::Switches;
use clap::{CommandFactory, Parser};

#[derive(Parser)]
#[command(name = "fluidform")]
struct Only {
    #[command(flatten)]
    s: Switches,
}

/// One switch as the overlay shows it.
pub struct Flag {
    /// Without the dashes: "list", "control-pressure".
    pub name: String,
    pub help: String,
    /// The closed set of values (enums), empty for numbers and text.
    pub values: Vec<String>,
    /// A switch without a value (e.g. --validation).
    pub boolean: bool,
    /// The clap group (the switch struct): "MetaballArgs", "ControlArgs", ...
    pub group: String,
}

/// Every switch of `run`, in the parser's order.
pub fn all() -> Vec<Flag> {
    let cmd = Only::command();
    let group_of = |id: &clap::Id| {
        cmd.get_groups()
            .find(|g| g.get_args().any(|a| a == id))
            .map(|g| g.get_id().to_string())
            .unwrap_or_default()
    };
    cmd.get_arguments()
        .filter_map(|a| {
            let name = a.get_long()?.to_string();
            let boolean = matches!(a.get_action(), clap::ArgAction::SetTrue);
            Some(Flag {
                values: (a.get_possible_values().iter())
                    .filter(|_| !boolean)
                    .map(|v| v.get_name().to_string())
                    .collect(),
                help: a.get_help().map(|h| h.to_string()).unwrap_or_default(),
                group: group_of(a.get_id()),
                boolean,
                name,
            })
        })
        .collect()
}

/// Parse `args` (["--list", "sbuffer", ...]) as `run` does; the parser's message on error.
pub fn parse(args: &[String]) -> Result<Switches, String> {
    let argv = std::iter::once("fluidform".to_string()).chain(args.iter().cloned());
    Only::try_parse_from(argv)
        .map(|o| o.s)
        .map_err(|e| e.to_string().lines().next().unwrap_or("").to_string())
}

/// The flags that give `sw`, as `run` would be given them (values that differ from the
/// parser's defaults), through the switches' serialisation: a new switch needs no code
/// here.
pub fn args_of(sw: &Switches) -> Vec<String> {
    let default = parse(&[]).unwrap_or_default();
    let (Ok(serde_json::Value::Object(now)), Ok(serde_json::Value::Object(base))) =
        (serde_json::to_value(sw), serde_json::to_value(&default))
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for (k, v) in &now {
        if base.get(k) == Some(v) || v.is_null() {
            continue;
        }
        let flag = format!("--{}", k.replace('_', "-"));
        match v {
            serde_json::Value::Bool(true) => out.push(flag),
            serde_json::Value::Bool(false) => {}
            // --fluid KEY=VALUE repeats; vectors and sizes are comma lists (WxH for sizes).
            serde_json::Value::Array(items) if k == "fluid" => {
                for i in items {
                    out.extend([flag.clone(), plain(i)]);
                }
            }
            serde_json::Value::Array(items) if k == "uv_size" => {
                let s: Vec<String> = items.iter().map(plain).collect();
                out.extend([flag, s.join("x")]);
            }
            serde_json::Value::Array(items) => {
                let s: Vec<String> = items.iter().map(plain).collect();
                out.extend([flag, s.join(",")]);
            }
            v => out.extend([flag, plain(v)]),
        }
    }
    out
}

fn plain(v: &serde_json::Value) -> String {
    match v {
        serde_json::Value::String(s) => s.clone(),
        v => v.to_string(),
    }
}

/// `args` with `--name value` set (None: removed, back to the default).
pub fn with(args: &[String], name: &str, value: Option<&str>) -> Vec<String> {
    let flag = format!("--{name}");
    let boolean = all().iter().any(|f| f.name == name && f.boolean);
    let mut out = Vec::new();
    let mut i = 0;
    while i < args.len() {
        if args[i] == flag && name != "fluid" {
            i += if boolean { 1 } else { 2 };
            continue;
        }
        out.push(args[i].clone());
        i += 1;
    }
    match (value, boolean) {
        (Some("false") | None, true) => {}
        (Some(_), true) => out.push(flag),
        (Some(v), false) => out.extend([flag, v.to_string()]),
        (None, false) => {}
    }
    out
}

/// The value `sw` (the switches as the scene applied them) has for `name`, as written.
pub fn value_in(sw: &Switches, name: &str) -> Option<String> {
    value_at(&serde_json::to_value(sw).ok()?, name)
}

/// The same, from the switches serialised once (the panel reads every flag a frame).
pub fn value_at(switches: &serde_json::Value, name: &str) -> Option<String> {
    match switches.get(name.replace('-', "_"))? {
        serde_json::Value::Null => None,
        serde_json::Value::Array(items) => {
            Some(items.iter().map(plain).collect::<Vec<_>>().join(","))
        }
        v => Some(plain(v)),
    }
}

/// Whether switches of `group` change only the picture: the view is rebuilt and the
/// simulation goes on. Any other switch rebuilds the scene.
pub fn view_only(group: &str) -> bool {
    matches!(group, "MetaballArgs" | "CameraArgs")
}

/// The `fluidform run` command line of `scene` with `args`.
pub fn command_line(scene: &str, args: &[String]) -> String {
    let quote = |a: &String| match a.contains([' ', '"', '\'']) {
        true => format!("'{a}'"),
        false => a.clone(),
    };
    let mut s = format!("fluidform run --scene {}", quote(&scene.to_string()));
    for a in args {
        s.push(' ');
        s.push_str(&quote(a));
    }
    s
}

/// The group a flag belongs to ("" when unknown).
pub fn group_of(name: &str) -> String {
    all()
        .into_iter()
        .find(|f| f.name == name)
        .map(|f| f.group)
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_round_trip_through_run_parser() {
        assert_eq!(group_of("list"), "MetaballArgs");
        assert_eq!(group_of("control-pressure"), "ControlArgs");
        assert_eq!(group_of("eye"), "CameraArgs");
        assert_eq!(group_of("nonsense"), "");
        let args: Vec<String> = [
            "--list",
            "abuffer",
            "--fluid",
            "viscosity=2",
            "--fluid",
            "eos=tait",
        ]
        .map(String::from)
        .into();
        let args = [
            args,
            ["--eye", "1,2,3", "--validation", "--uv-size", "64x32"]
                .map(String::from)
                .into(),
        ]
        .concat();
        let sw = parse(&args).unwrap();
        let back = parse(&args_of(&sw)).unwrap();
        assert_eq!(
            serde_json::to_value(&sw).unwrap(),
            serde_json::to_value(&back).unwrap()
        );
        let flipped = with(&args_of(&sw), "list", Some("sbuffer"));
        assert_eq!(
            value_in(&parse(&flipped).unwrap(), "list").as_deref(),
            Some("sbuffer")
        );
        let unset = with(&flipped, "validation", None);
        assert_eq!(
            value_in(&parse(&unset).unwrap(), "validation").as_deref(),
            Some("false")
        );
        assert!(parse(&with(&args, "list", Some("cbuffer"))).is_err());
        assert_eq!(
            value_in(&sw, "fluid").as_deref(),
            Some("viscosity=2,eos=tait")
        );
    }
}
