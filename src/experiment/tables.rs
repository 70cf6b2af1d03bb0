//! Thesis tables 2-8 (seed 000, section 5): the same rows and columns, the thesis's frame
//! rates (K1 = GTX 1660 Ti laptop, K2 = GTX 1080 Ti desktop) and list memory beside ours.
use super::Experiment;
use crate::render::metaball::MetaballSettings;
use crate::render::{DensityFn, ListKind, Material};

/// A column: one metaball list (the S-buffer as the thesis built it, unsorted, or ours
/// with its ranges sorted by depth).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Col {
    pub name: &'static str,
    pub list: ListKind,
    pub sorted: bool,
}

pub const NONE: Col = Col {
    name: "none",
    list: ListKind::None,
    sorted: false,
};
pub const ABUFFER: Col = Col {
    name: "abuffer",
    list: ListKind::Abuffer,
    sorted: false,
};
pub const SBUFFER: Col = Col {
    name: "sbuffer",
    list: ListKind::Sbuffer,
    sorted: false,
};
pub const SBUFFER_SORTED: Col = Col {
    name: "sbuffer-sorted",
    list: ListKind::Sbuffer,
    sorted: true,
};

/// The thesis's numbers in one cell: frames per second on K1 and K2 as printed (a single
/// value, a range "103-105", or empty where the thesis gives none).
#[derive(Clone, Debug, Default)]
pub struct Thesis {
    pub k1: &'static str,
    pub k2: &'static str,
}

/// Midpoint of a printed value or range.
pub fn value(s: &str) -> Option<f64> {
    let mut it = s.split('-').map(|x| x.trim().parse::<f64>().ok());
    match (it.next().flatten(), it.next().flatten()) {
        (Some(a), Some(b)) => Some(0.5 * (a + b)),
        (Some(a), None) => Some(a),
        _ => None,
    }
}

/// What a row changes from the thesis defaults (Wyvill, T 0.9, R 0.04, I 2, Phong, depth 1).
#[derive(Clone, Debug, Default)]
pub struct Change {
    pub material: Option<Material>,
    pub density: Option<DensityFn>,
    pub threshold: Option<f32>,
    pub radius: Option<f32>,
    pub refine: Option<u32>,
    pub depth: Option<u32>,
    /// Particles as a multiple of the base count (table 8).
    pub particles: Option<f64>,
}

impl Change {
    pub fn apply(&self, s: &mut MetaballSettings) {
        if let Some(m) = self.material {
            s.material = m;
        }
        if let Some(d) = self.density {
            s.density = d;
        }
        if let Some(t) = self.threshold {
            s.threshold = t;
        }
        if let Some(r) = self.radius {
            s.radius = r;
            s.step = r / 8.0;
        }
        if let Some(i) = self.refine {
            s.refine = i;
        }
        if let Some(d) = self.depth {
            s.depth = d;
        }
    }
}

pub struct RowDef {
    pub label: String,
    pub change: Change,
    /// One per column of the table.
    pub thesis: Vec<Thesis>,
    /// The thesis's list memory, A-buffer and S-buffer, MB.
    pub memory: (&'static str, &'static str),
}

pub struct TableDef {
    pub name: Experiment,
    pub title: &'static str,
    /// The thesis's configuration for this table, and how ours differs.
    pub notes: Vec<&'static str>,
    pub cols: Vec<Col>,
    pub rows: Vec<RowDef>,
    /// Axes whose cost should rise along the rows, as (claim, groups of row indices in
    /// increasing order of the axis).
    pub rises: Vec<(&'static str, Vec<Vec<usize>>)>,
    /// Image sheet: columns of tiles (0: none).
    pub sheet_cols: usize,
}

fn t(k1: &'static str, k2: &'static str) -> Thesis {
    Thesis { k1, k2 }
}

fn k2(v: [&'static str; 3]) -> Vec<Thesis> {
    v.iter().map(|&x| t("", x)).collect()
}

/// The definition of a thesis table; None for an experiment that is no table.
pub fn def(e: Experiment) -> Option<TableDef> {
    Some(match e {
        Experiment::Table2 => table2(),
        Experiment::Table3 => table3(),
        Experiment::Table4 => table4(),
        Experiment::Table5 => table5(),
        Experiment::Table6 => table6(),
        Experiment::Table7 => table7(),
        Experiment::Table8 => table8(),
        _ => return None,
    })
}

fn table2() -> TableDef {
    let three = vec![NONE, ABUFFER, SBUFFER];
    let m = |label: &str, mat, depth: Option<u32>, v: [(&'static str, &'static str); 3]| RowDef {
        label: label.into(),
        change: Change {
            material: Some(mat),
            depth,
            ..Change::default()
        },
        thesis: v.iter().map(|&(a, b)| t(a, b)).collect(),
        memory: ("8.7", "5.8"),
    };
    TableDef {
            name: Experiment::Table2,
            title: "Table 2: materials x metaball lists",
            notes: vec![
                "Transparent is `--material glass`, partially transparent `--material tinted`, both at recursion depth 2: the thesis does not give table 2's depth, and its 65 fps (K2, S-buffer) lies between its depth-2 and depth-3 rows of tables 6 and 7.",
            ],
            cols: three,
            rows: vec![
                m("Phong", Material::Phong, None, [("9", "11"), ("45", "87"), ("52", "98")]),
                m("transparent", Material::Glass, Some(2), [("4", "5"), ("33", "47"), ("40", "65")]),
                m("partially transparent", Material::Tinted, Some(2), [("4", "5"), ("33", "47"), ("40", "65")]),
                m("gold", Material::Gold, None, [("9", "11"), ("51", "87"), ("54", "98")]),
                m("copper", Material::Copper, None, [("9", "11"), ("50", "87"), ("54", "98")]),
                m("aluminium", Material::Aluminium, None, [("8", "11"), ("50", "87"), ("54", "98")]),
            ],
            rises: vec![],
            sheet_cols: 3,
        }
}

fn table3() -> TableDef {
    let three = vec![NONE, ABUFFER, SBUFFER];
    let d = |label: &str, f, v: [&'static str; 3]| RowDef {
        label: label.into(),
        change: Change {
            density: Some(f),
            ..Change::default()
        },
        memory: match v[0].is_empty() {
            true => ("", ""),
            false => ("9", "6"),
        },
        thesis: k2(v),
    };
    TableDef {
        name: Experiment::Table3,
        title: "Table 3: density functions x metaball lists (Phong)",
        notes: vec![
            "The thesis's \"original\" is Blinn's Gaussian truncated at R (`--density blinn`).",
        ],
        cols: three,
        rows: vec![
            d("original (Blinn)", DensityFn::Blinn, ["11", "83", "95"]),
            d("Wyvill", DensityFn::Wyvill, ["11", "87", "98"]),
            d("Nishimura", DensityFn::Nishimura, ["10", "87", "97"]),
            d("Murakami", DensityFn::Murakami, ["10", "88", "98"]),
            // Ours (not in the thesis): Wendland's C2, the worked example of adding a variant.
            d("Wendland (ours)", DensityFn::Wendland, ["", "", ""]),
        ],
        rises: vec![],
        sheet_cols: 4,
    }
}

fn table4() -> TableDef {
    let three = vec![NONE, ABUFFER, SBUFFER];
    let mut rows = Vec::new();
    let radii = [
        (0.03, "103-105", ("6.2", "4.6")),
        (0.04, "98-101", ("12.7", "7.9")),
        (0.05, "91-93", ("15.2", "9.1")),
    ];
    for &(r, s, mem) in &radii {
        for tt in [1.5f32, 0.9, 0.2] {
            rows.push(RowDef {
                label: format!("R={r} T={tt}"),
                change: Change {
                    radius: Some(r),
                    threshold: Some(tt),
                    ..Change::default()
                },
                thesis: vec![t("", "11-12"), t("", ""), t("", s)],
                memory: mem,
            });
        }
    }
    let by_t = (0..3)
        .map(|ti| (0..3).map(|ri| ri * 3 + ti).collect())
        .collect();
    TableDef {
            name: Experiment::Table4,
            title: "Table 4: threshold T x radius R (Wyvill, Phong)",
            notes: vec![
                "The thesis prints one range per radius over the three thresholds (K2, S-buffer), A-buffer memory per radius, and none at 11-12 fps throughout; it gives no A-buffer frame rates.",
                "R is in metres beside our fluid's rest spacing of 0.0272 m (Kelager's water); the thesis's spacing is not given, so at R = 0.03 and T = 1.5 the field may stay below T and show little or nothing.",
            ],
            cols: three,
            rows,
            rises: vec![("cost rises with the radius R", by_t)],
            sheet_cols: 3,
        }
}

fn table5() -> TableDef {
    let three = vec![NONE, ABUFFER, SBUFFER];
    let rows = [
        (0u32, ["14", "97", "101"]),
        (2, ["13", "93", "98"]),
        (4, ["9", "86", "99"]),
    ]
    .iter()
    .map(|&(i, v)| RowDef {
        label: format!("I={i}"),
        change: Change {
            refine: Some(i),
            ..Change::default()
        },
        thesis: k2(v),
        memory: ("", ""),
    })
    .collect();
    TableDef {
        name: Experiment::Table5,
        title: "Table 5: binary refinement steps I (Phong)",
        notes: vec![],
        cols: three,
        rows,
        rises: vec![(
            "cost rises with the refinement steps I",
            vec![vec![0, 1, 2]],
        )],
        sheet_cols: 0,
    }
}

fn table6() -> TableDef {
    let four = vec![NONE, ABUFFER, SBUFFER, SBUFFER_SORTED];
    let mut rows = Vec::new();
    let data = [
        (
            1u32,
            [["12", "92", "100"], ["10", "89", "98"], ["8", "86", "97"]],
        ),
        (3, [["3", "39", "57"], ["2", "38", "53"], ["2", "37", "52"]]),
    ];
    for (depth, per_i) in data {
        for (k, i) in [0u32, 2, 4].into_iter().enumerate() {
            let mut th = k2(per_i[k]);
            th.push(Thesis::default());
            rows.push(RowDef {
                label: format!("depth {depth} I={i}"),
                change: Change {
                    material: Some(Material::Glass),
                    depth: Some(depth),
                    refine: Some(i),
                    ..Change::default()
                },
                thesis: th,
                memory: ("", ""),
            });
        }
    }
    TableDef {
            name: Experiment::Table6,
            title: "Table 6: transparent (glass), recursion depth 1 and 3 x refinement I",
            notes: vec!["sbuffer-sorted is ours (S-buffer ranges sorted by view depth, each sample summing the metaballs within R of its depth); the thesis has no such column."],
            cols: four,
            rows,
            rises: vec![
                ("cost rises with the refinement steps I", vec![vec![0, 1, 2], vec![3, 4, 5]]),
                ("cost rises with the recursion depth", vec![vec![0, 3], vec![1, 4], vec![2, 5]]),
            ],
            sheet_cols: 0,
        }
}

fn table7() -> TableDef {
    let four = vec![NONE, ABUFFER, SBUFFER, SBUFFER_SORTED];
    let rows = [
        (1u32, ["12", "92", "101"]),
        (2, ["5", "58", "72"]),
        (3, ["3", "46", "60"]),
    ]
    .iter()
    .map(|&(d, v)| {
        let mut th = k2(v);
        th.push(Thesis::default());
        RowDef {
            label: format!("depth {d}"),
            change: Change {
                material: Some(Material::Tinted),
                depth: Some(d),
                refine: Some(0),
                ..Change::default()
            },
            thesis: th,
            memory: ("", ""),
        }
    })
    .collect();
    TableDef {
        name: Experiment::Table7,
        title: "Table 7: partially transparent (tinted), recursion depth 1-3, I = 0",
        notes: vec!["sbuffer-sorted is ours, as in table 6."],
        cols: four,
        rows,
        rises: vec![("cost rises with the recursion depth", vec![vec![0, 1, 2]])],
        sheet_cols: 0,
    }
}

fn table8() -> TableDef {
    let three = vec![NONE, ABUFFER, SBUFFER];
    let rows = [
        (0.5, ["22", "200", "213"], ("3.6", "3.3")),
        (1.0, ["11", "95", "104"], ("8.2", "5.6")),
        (2.0, ["6", "40", "42"], ("12", "7.5")),
    ]
    .iter()
    .map(|&(f, v, mem)| RowDef {
        label: format!("{}x", f),
        change: Change {
            particles: Some(f),
            ..Change::default()
        },
        thesis: k2(v),
        memory: mem,
    })
    .collect();
    TableDef {
            name: Experiment::Table8,
            title: "Table 8: particle count (Phong)",
            notes: vec!["The same walker and camera filled with half, the same and twice the particles (the thesis's 1024, 2048, 4096): the spacing shrinks, the metaball radius stays."],
            cols: three,
            rows,
            rises: vec![(
                "cost rises with the particle count N",
                vec![vec![0, 1, 2]],
            )],
            sheet_cols: 0,
        }
}
