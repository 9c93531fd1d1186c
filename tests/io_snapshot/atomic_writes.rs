//! Every writer replaces its target atomically and leaves no temporary file, also when it fails.

use super::*;
use dustdem::output::snapshot::{write_lammps_dump, write_pvd, write_vtu, write_walls_vtp};

#[test]
fn atomic_write_leaves_only_the_target_and_replaces_it() {
    let dir = TempDir::new("atomic");
    let d = data(100, 11);
    let s = snapshot(&d);
    let path = dir.path("snap.vtu");
    fs::write(&path, "stale").unwrap();
    write_vtu(&path, &s).unwrap();
    write_lammps_dump(&dir.path("snap.dump"), &s).unwrap();
    write_walls_vtp(&dir.path("walls.vtp"), &d.walls, ([-1.0; 3], [1.0; 3])).unwrap();
    write_pvd(&dir.path("run.pvd"), &[(0.0, "snap.vtu".into())]).unwrap();
    assert_eq!(
        dir.entries(),
        vec!["run.pvd", "snap.dump", "snap.vtu", "walls.vtp"]
    );
    assert!(fs::read_to_string(&path).unwrap().starts_with("<?xml"));

    // A write that fails at the file system leaves nothing behind either, and says where.
    let missing = dir.path("no-such-dir").join("x.vtu");
    let msg = write_vtu(&missing, &s).unwrap_err().to_string();
    assert!(msg.contains("no-such-dir"), "{msg}");
    assert_eq!(dir.entries().len(), 4);

    // A write that fails after the temporary file exists (here the final rename, because a
    // directory is in the way) removes it again.
    fs::create_dir(dir.path("blocked.vtu")).unwrap();
    assert!(write_vtu(&dir.path("blocked.vtu"), &s).is_err());
    assert_eq!(
        dir.entries(),
        vec![
            "blocked.vtu",
            "run.pvd",
            "snap.dump",
            "snap.vtu",
            "walls.vtp"
        ]
    );
}
