//! Time series as a ParaView data collection (`.pvd`): a small XML file of type `Collection`
//! listing one `DataSet` per frame, with its simulated time as `timestep` and its file
//! relative to the collection. ParaView's PVD reader (vtkPVDReader) reads it and offers the
//! frames at those times ("ParaView/Data formats", PVD file format, on the ParaView wiki);
//! the files it lists must be VTK XML files, such as the frames of [`super::write_vtp`].

use crate::Error;
use std::path::Path;

/// One entry of a collection: a data file and the simulated time it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct PvdDataSet {
    /// Simulated time of the data (s).
    pub time: f64,
    /// The data file's path relative to the directory of the `.pvd` (`/` separates
    /// directories).
    pub file: String,
}

/// Writes the collection of `datasets`, in their order, to `path`, replacing it whole
/// ([`super::write_atomically`]): a run interrupted at any point leaves the previous
/// collection or this one, never part of one. Times are printed so that they read back
/// exactly. Errors name a time that is not finite, or the path.
pub fn write_pvd(path: &Path, datasets: &[PvdDataSet]) -> Result<(), Error> {
    let mut text = String::from(
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  \
         <Collection>\n",
    );
    for (i, dataset) in datasets.iter().enumerate() {
        if !dataset.time.is_finite() {
            let field = format!("datasets[{i}].time");
            return Err(Error::invalid(field, dataset.time, "must be finite"));
        }
        // Rust's `{}` of an f64 is the shortest decimal that parses back to the same value.
        text += &format!(
            "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            dataset.time,
            escape(&dataset.file)
        );
    }
    text += "  </Collection>\n</VTKFile>\n";
    super::write_atomically(path, text.as_bytes())
}

/// `value` fit for a double-quoted XML attribute: the characters XML 1.0 §2.4 and §3.3.3
/// give a meaning there replaced by character references.
fn escape(value: &str) -> String {
    let mut out = String::with_capacity(value.len());
    for c in value.chars() {
        match c {
            '&' => out += "&amp;",
            '<' => out += "&lt;",
            '>' => out += "&gt;",
            '"' => out += "&quot;",
            '\'' => out += "&apos;",
            '\t' => out += "&#9;",
            '\n' => out += "&#10;",
            '\r' => out += "&#13;",
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("projfluid-pvd-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// The (timestep, file) of every `DataSet`, parsed as XML.
    fn read_pvd(path: &Path) -> Vec<(f64, String)> {
        let text = std::fs::read_to_string(path).unwrap();
        let doc = roxmltree::Document::parse(&text).unwrap();
        assert_eq!(doc.root_element().attribute("type"), Some("Collection"));
        doc.descendants()
            .filter(|n| n.has_tag_name("DataSet"))
            .map(|n| {
                let time = n.attribute("timestep").unwrap().parse().unwrap();
                (time, n.attribute("file").unwrap().to_string())
            })
            .collect()
    }

    /// Times read back exactly, file names survive characters XML gives a meaning, and a
    /// rewrite replaces the collection whole, leaving no temporary file behind.
    #[test]
    fn collection_reads_back_and_is_replaced_whole() {
        let dir = temp_dir("read-back");
        let path = dir.join("frames.pvd");
        let datasets = vec![
            PvdDataSet {
                time: 0.0,
                file: "frame_00000.vtp".into(),
            },
            PvdDataSet {
                time: 0.1 + 0.2,
                file: "a & b/\"<c>\".vtp".into(),
            },
            PvdDataSet {
                time: 1e-7 / 3.0,
                file: "frame_00002.vtp".into(),
            },
        ];
        write_pvd(&path, &datasets).unwrap();
        let read: Vec<(f64, String)> = datasets.iter().map(|d| (d.time, d.file.clone())).collect();
        assert_eq!(read_pvd(&path), read);

        write_pvd(&path, &datasets[..1]).unwrap();
        assert_eq!(read_pvd(&path), read[..1]);
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["frames.pvd"]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_times_and_paths_are_named() {
        let dir = temp_dir("bad");
        let path = dir.join("frames.pvd");
        let nan = PvdDataSet {
            time: f64::NAN,
            file: "f.vtp".into(),
        };
        let err = write_pvd(&path, &[nan]).unwrap_err();
        assert_eq!(err.to_string(), "datasets[0].time must be finite, got NaN");
        assert!(!path.exists(), "a rejected collection writes nothing");
        std::fs::remove_dir_all(&dir).unwrap();
        let err = write_pvd(Path::new("/nonexistent-dir/frames.pvd"), &[]).unwrap_err();
        let message = err.to_string();
        assert!(message.contains("/nonexistent-dir/frames.pvd"), "{message}");
    }
}
