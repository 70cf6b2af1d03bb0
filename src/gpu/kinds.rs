//! Closed sets of choices (`Kind`, declared with `switch_enum!`): each parses and prints as
//! its switch spells it, and gives its shader defines. This layer declares only its own
//! (the primitives' sorts and neighbour searches); each domain declares its choices beside
//! it (the solvers in sph, the list modes in render, ...), and the command line offers them.
/// A closed set of choices: every value, and each one's name as its switch spells it
/// (kebab case). The command line offers them through `Kind`, so no layer below it needs
/// the command-line parser.
pub trait Kind: Copy + Eq + std::str::FromStr<Err = String> + 'static {
    /// Every value, in declaration order (their shader indices).
    const ALL: &'static [Self];
    /// The name as written on the command line and in scene files.
    fn as_str(self) -> String;
}

/// `OddEven` -> `odd-even`, `Eq8` -> `eq8`: the switch spelling of a variant's name.
pub fn kebab(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                out.push('-');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// Declare a `Kind`: the enum, its switch names, parsing with an error that lists them,
/// and `defines` for a shader's runtime switch.
#[macro_export]
macro_rules! switch_enum {
    ($(#[$m:meta])* $name:ident { $($v:ident),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
        #[serde(rename_all = "kebab-case")]
        pub enum $name { $($v),+ }
        impl $crate::kinds::Kind for $name {
            const ALL: &'static [Self] = &[$(Self::$v),+];
            fn as_str(self) -> String {
                match self { $(Self::$v => $crate::kinds::kebab(stringify!($v))),+ }
            }
        }
        impl $name {
            /// The switch value as written on the command line.
            pub fn as_str(self) -> String {
                <Self as $crate::kinds::Kind>::as_str(self)
            }
            /// Every value, in declaration order.
            pub fn all() -> &'static [Self] {
                <Self as $crate::kinds::Kind>::ALL
            }
            /// A shader's switch on this value: `NAME` = its value, and `NAME_VARIANT` = each
            /// variant's (what the GLSL compares against; a switch ends in `#error`).
            pub fn define(self, name: &str) -> Vec<(String, String)> {
                let mut d = vec![(name.to_string(), (self as u32).to_string())];
                d.extend(Self::defines(name));
                d
            }
            /// `PREFIX_NAME` = value for every variant, for a shader's runtime switch.
            pub fn defines(prefix: &str) -> Vec<(String, String)> {
                let names: Vec<(String, u32)> = Self::all()
                    .iter()
                    .map(|v| (v.as_str(), *v as u32))
                    .collect();
                let refs: Vec<(&str, u32)> = names.iter().map(|(n, v)| (n.as_str(), *v)).collect();
                $crate::interface::enum_defines(prefix, &refs)
            }
        }
        impl std::str::FromStr for $name {
            type Err = String;
            fn from_str(s: &str) -> Result<Self, String> {
                Self::all().iter().copied().find(|v| v.as_str() == s).ok_or_else(|| {
                    let names: Vec<String> = Self::all().iter().map(|v| v.as_str()).collect();
                    format!("'{s}' is none of {}", names.join(", "))
                })
            }
        }
        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str(&self.as_str())
            }
        }
    };
}

switch_enum!(SortAlgo {
    OddEven,
    Bitonic,
    Counting,
    None
});

switch_enum!(Neighbors { Morton, Grid, Hash });
