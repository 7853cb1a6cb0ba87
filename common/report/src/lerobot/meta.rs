//! The dataset's `meta/` folder: `info.json` (the features with their dtypes, shapes
//! and names), `stats.json`, `tasks.parquet` and the episodes' table, as LeRobot
//! v3.0's `lerobot_dataset.py` and `datasets/utils.py` write them.

use super::features::{Layout, FEATURES};
use super::runs::Meta;
use super::stats::{Stats, NAMES};
use super::table::{Cell, Col, Table};
use crate::Error;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};

/// LeRobot's dataset version this export writes.
pub const CODEBASE_VERSION: &str = "v3.0";
/// LeRobot's files per chunk folder.
pub const CHUNKS_SIZE: u64 = 1000;
/// LeRobot's data file size, MB of values: a file is closed past it, at an episode's end.
pub const DATA_FILES_SIZE_IN_MB: u64 = 100;
/// LeRobot's video file size, MB (no video here; written as LeRobot writes it).
pub const VIDEO_FILES_SIZE_IN_MB: u64 = 500;
/// `info.json`'s data path.
pub const DATA_PATH: &str = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet";

/// The per-frame columns every LeRobot dataset has, after the features, with their dtype.
pub const DEFAULTS: [(&str, &str); 5] = [
    ("timestamp", "float32"),
    ("frame_index", "int64"),
    ("episode_index", "int64"),
    ("index", "int64"),
    ("task_index", "int64"),
];

/// A data file's path under the dataset's root.
pub fn data_file(chunk: u64, file: u64) -> PathBuf {
    PathBuf::from(format!("data/chunk-{chunk:03}/file-{file:03}.parquet"))
}

/// One exported episode.
#[derive(Debug, Clone)]
pub struct Episode {
    /// The run it came from.
    pub run: PathBuf,
    /// Its task's text.
    pub task: String,
    /// Its task's index in `tasks.parquet`.
    pub task_index: i64,
    /// Frames.
    pub length: u64,
    /// The data file it is in, (chunk, file).
    pub file: (u64, u64),
    /// Its first frame's dataset index.
    pub from: u64,
    /// The run's conditions.
    pub meta: Meta,
    /// The swept keys' values.
    pub swept: Vec<(String, String)>,
    /// The sample at which a damaged record ended it, if one did.
    pub damaged_at: Option<u64>,
    /// Its statistics, the features' then [`DEFAULTS`]'.
    pub stats: Vec<Stats>,
}

/// The features of `info.json`: the five float vectors with their names and units,
/// then the default columns.
pub fn features(layout: &Layout) -> Value {
    let mut out = Map::new();
    for (name, entries) in FEATURES.iter().zip(layout.entries()) {
        let names: Vec<&str> = entries.iter().map(|(n, _)| n.as_str()).collect();
        let units: Vec<&str> = entries.iter().map(|(_, u)| u.as_str()).collect();
        out.insert(
            (*name).to_string(),
            json!({
                "dtype": "float32",
                "shape": [entries.len()],
                "names": names,
                "info": {"units": units},
            }),
        );
    }
    for (name, dtype) in DEFAULTS {
        out.insert(
            name.to_string(),
            json!({"dtype": dtype, "shape": [1], "names": null}),
        );
    }
    Value::Object(out)
}

/// `info.json`, its keys as LeRobot's `create_empty_dataset_info` makes them.
pub fn info(layout: &Layout, fps: u32, episodes: usize, frames: u64, tasks: usize) -> Value {
    json!({
        "codebase_version": CODEBASE_VERSION,
        "robot_type": "tactile",
        "total_episodes": episodes,
        "total_frames": frames,
        "total_tasks": tasks,
        "chunks_size": CHUNKS_SIZE,
        "data_files_size_in_mb": DATA_FILES_SIZE_IN_MB,
        "video_files_size_in_mb": VIDEO_FILES_SIZE_IN_MB,
        "fps": fps,
        "splits": {"train": format!("0:{episodes}")},
        "data_path": DATA_PATH,
        "video_path": null,
        "features": features(layout),
    })
}

/// The Hugging Face `datasets` schema a data file carries in its footer (key
/// `huggingface`), so `datasets` reads the vectors as fixed-length lists, as it
/// reads a LeRobot recorder's.
pub fn hf_features(layout: &Layout) -> String {
    let mut out = Map::new();
    for (name, entries) in FEATURES.iter().zip(layout.entries()) {
        out.insert(
            (*name).to_string(),
            json!({"feature": {"dtype": "float32", "_type": "Value"}, "length": entries.len(), "_type": "List"}),
        );
    }
    for (name, dtype) in DEFAULTS {
        out.insert(name.to_string(), json!({"dtype": dtype, "_type": "Value"}));
    }
    json!({"info": {"features": out}}).to_string()
}

/// The names of all statistics' features, in [`Episode::stats`]' order.
pub fn stat_names() -> Vec<&'static str> {
    FEATURES
        .iter()
        .copied()
        .chain(DEFAULTS.iter().map(|(n, _)| *n))
        .collect()
}

/// `stats.json`: each feature's statistics over the whole dataset.
pub fn stats_json(all: &[Stats]) -> Value {
    let mut out = Map::new();
    for (name, s) in stat_names().into_iter().zip(all) {
        out.insert(name.to_string(), s.to_json());
    }
    Value::Object(out)
}

fn io(what: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |e| Error::Io {
        context: format!("writing {}", what.display()),
        source: e,
    }
}

/// `meta/tasks.parquet`: the task texts as the index (pandas' `__index_level_0__`,
/// as a LeRobot recorder's file has it) and their `task_index`.
pub fn write_tasks(path: &Path, tasks: &[String]) -> Result<(), Error> {
    let cols = vec![
        ("task_index".to_string(), Col::I64),
        ("__index_level_0__".to_string(), Col::Str),
    ];
    let mut t = Table::create(path, cols).map_err(io(path))?;
    for (k, task) in tasks.iter().enumerate() {
        t.add(&[Cell::I64(k as i64), Cell::Str(task.clone())])
            .map_err(io(path))?;
    }
    let pandas = json!({
        "index_columns": ["__index_level_0__"],
        "column_indexes": [{"name": null, "field_name": null, "pandas_type": "unicode", "numpy_type": "object", "metadata": {"encoding": "UTF-8"}}],
        "columns": [
            {"name": "task_index", "field_name": "task_index", "pandas_type": "int64", "numpy_type": "int64", "metadata": null},
            {"name": null, "field_name": "__index_level_0__", "pandas_type": "unicode", "numpy_type": "object", "metadata": null},
        ],
        "attributes": {},
        "creator": {"library": "tactile", "version": env!("CARGO_PKG_VERSION")},
        "pandas_version": "2.0.0",
    });
    t.finish(&[("pandas", pandas.to_string())])
        .map_err(io(path))
}

/// The episodes' table's columns: LeRobot's, then Tactile's own (`tactile/...`).
fn episode_columns() -> Vec<(String, Col)> {
    let mut cols: Vec<(String, Col)> = [
        ("episode_index", Col::I64),
        ("tasks", Col::ListStr),
        ("length", Col::I64),
        ("data/chunk_index", Col::I64),
        ("data/file_index", Col::I64),
        ("dataset_from_index", Col::I64),
        ("dataset_to_index", Col::I64),
    ]
    .map(|(n, c)| (n.to_string(), c))
    .to_vec();
    for f in stat_names() {
        for s in NAMES {
            let col = if s == "count" {
                Col::ListI64
            } else {
                Col::ListF64
            };
            cols.push((format!("stats/{f}/{s}"), col));
        }
    }
    cols.extend(
        [
            ("meta/episodes/chunk_index", Col::I64),
            ("meta/episodes/file_index", Col::I64),
            ("tactile/run", Col::Str),
            ("tactile/control", Col::Str),
            ("tactile/codec_forward", Col::Str),
            ("tactile/codec_backward", Col::Str),
            ("tactile/delay_forward_ms", Col::OptF64),
            ("tactile/delay_backward_ms", Col::OptF64),
            ("tactile/loss_forward", Col::OptF64),
            ("tactile/loss_backward", Col::OptF64),
            ("tactile/task_success", Col::OptBool),
            ("tactile/completion_s", Col::OptF64),
            ("tactile/damaged_at_sample", Col::OptI64),
            ("tactile/swept", Col::Str),
        ]
        .map(|(n, c)| (n.to_string(), c)),
    );
    cols
}

/// One episode's row of the episodes' table.
fn episode_row(k: usize, e: &Episode) -> Vec<Cell> {
    let mut row = vec![
        Cell::I64(k as i64),
        Cell::ListStr(vec![e.task.clone()]),
        Cell::I64(e.length as i64),
        Cell::I64(e.file.0 as i64),
        Cell::I64(e.file.1 as i64),
        Cell::I64(e.from as i64),
        Cell::I64((e.from + e.length) as i64),
    ];
    for s in &e.stats {
        row.extend(s.columns().map(Cell::ListF64));
        row.push(Cell::ListI64(vec![s.count() as i64]));
    }
    let swept: Map<String, Value> = e
        .swept
        .iter()
        .map(|(k, v)| (k.clone(), Value::String(v.clone())))
        .collect();
    let m = &e.meta;
    row.extend([
        Cell::I64(0),
        Cell::I64(0),
        Cell::Str(e.run.display().to_string()),
        Cell::Str(m.control.clone()),
        Cell::Str(m.codec_forward.clone()),
        Cell::Str(m.codec_backward.clone()),
        Cell::OptF64(Some(m.delay_forward_ms)),
        Cell::OptF64(Some(m.delay_backward_ms)),
        Cell::OptF64(Some(m.loss_forward)),
        Cell::OptF64(Some(m.loss_backward)),
        Cell::OptBool(m.task_success),
        Cell::OptF64(m.completion_s),
        Cell::OptI64(e.damaged_at.map(|n| n as i64)),
        Cell::Str(Value::Object(swept).to_string()),
    ]);
    row
}

/// `meta/episodes/chunk-000/file-000.parquet`: one row per episode.
pub fn write_episodes(path: &Path, episodes: &[Episode]) -> Result<(), Error> {
    let mut t = Table::create(path, episode_columns()).map_err(io(path))?;
    for (k, e) in episodes.iter().enumerate() {
        t.add(&episode_row(k, e)).map_err(io(path))?;
    }
    t.finish(&[]).map_err(io(path))
}
