//! The `.pvd` collection lists every step with its time and escapes file names.

use super::*;
use dustdem::output::snapshot::write_pvd;

/// Attribute value of `attr` in an XML start tag, unescaping the five predefined entities.
fn attr(tag: &str, attr: &str) -> String {
    let key = format!(" {attr}=\"");
    let start = tag.find(&key).unwrap() + key.len();
    let end = start + tag[start..].find('"').unwrap();
    tag[start..end]
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

#[test]
fn pvd_lists_every_step_with_its_time() {
    let dir = TempDir::new("pvd");
    let entries: Vec<(f64, String)> = vec![
        (0.0, "snap_000000.vtu".into()),
        (1.0e-7 / 3.0, "snap_000001.vtu".into()),
        (2.5e-3, "odd <&\"'> name.vtu".into()),
        // Only a correctly escaping writer gets this back unchanged.
        (3.0e-3, "a&lt;b.vtu".into()),
    ];
    let path = dir.path("run.pvd");
    write_pvd(&path, &entries).unwrap();

    let xml = fs::read_to_string(&path).unwrap();
    assert!(xml.contains(r#"type="Collection""#));
    let tags: Vec<&str> = xml
        .split("<DataSet ")
        .skip(1)
        .map(|t| &t[..t.find("/>").unwrap()])
        .collect();
    assert_eq!(tags.len(), entries.len());
    for ((time, file), tag) in entries.iter().zip(&tags) {
        let tag = format!(" {tag}");
        let t: f64 = attr(&tag, "timestep").parse().unwrap();
        assert_eq!(t.to_bits(), time.to_bits());
        assert_eq!(&attr(&tag, "file"), file);
    }

    assert!(write_pvd(&path, &[(f64::NAN, "x.vtu".into())]).is_err());
}
