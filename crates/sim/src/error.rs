//! Errors of the simulation core. Every message names the file, line, tet or node to fix.

use std::path::PathBuf;

/// Why a mesh could not be read or built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be opened or read.
    #[error("{path}: {source}")]
    Io {
        /// File that failed.
        path: PathBuf,
        /// Underlying OS error.
        source: std::io::Error,
    },
    /// The file's content is malformed at a given line (1-based).
    #[error("{path}:{line}: {message}")]
    Parse {
        /// File (or a descriptive origin for in-memory text).
        path: PathBuf,
        /// 1-based line number; 0 when the problem is the end of the file.
        line: usize,
        /// What is wrong there.
        message: String,
    },
    /// The file extension names no supported format.
    #[error("{path}: unsupported mesh format (expected .node/.ele, .msh, .vtk or .vtu)")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// The mesh has no nodes or no tetrahedra.
    #[error("mesh has {nodes} nodes and {tets} tetrahedra; at least 4 nodes and 1 tet are needed")]
    Empty {
        /// Node count.
        nodes: usize,
        /// Tet count.
        tets: usize,
    },
    /// A tet references a node that does not exist.
    #[error("tet {tet} references node {node}, but the mesh has {count} nodes")]
    NodeIndexOutOfRange {
        /// Tet index (0-based).
        tet: usize,
        /// Offending node index (0-based).
        node: u64,
        /// Number of nodes.
        count: usize,
    },
    /// A tet uses the same node twice.
    #[error("tet {tet} repeats node {node}")]
    RepeatedNode {
        /// Tet index (0-based).
        tet: usize,
        /// Node that appears twice.
        node: u32,
    },
    /// A tet's volume is (nearly) zero: it cannot carry rest data.
    #[error(
        "tet {tet} is degenerate: volume {volume:e} m^3 is below the tolerance {tolerance:e} m^3"
    )]
    DegenerateTet {
        /// Tet index (0-based).
        tet: usize,
        /// Its signed volume.
        volume: f64,
        /// The tolerance it failed.
        tolerance: f64,
    },
    /// A coordinate is NaN or infinite.
    #[error("node {node} has a non-finite coordinate")]
    NonFiniteNode {
        /// Node index (0-based).
        node: usize,
    },
}

impl MeshError {
    /// A parse error at `line` (1-based) of `path`.
    pub fn parse(path: impl Into<PathBuf>, line: usize, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.into(),
            line,
            message: message.into(),
        }
    }
}
