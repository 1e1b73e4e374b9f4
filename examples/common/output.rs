//! Where an example writes its files.

use std::path::PathBuf;

/// The output directory of example `name`: the value of `--out DIR` among `args`, else
/// `$HDI_OUT_DIR/name`, else `out/name` below the current directory. It is created if missing.
pub fn out_dir(name: &str, args: &[String]) -> Result<PathBuf, Box<dyn std::error::Error>> {
    let dir = match args.iter().position(|a| a == "--out") {
        Some(i) => PathBuf::from(args.get(i + 1).ok_or("--out needs a directory")?),
        None => match std::env::var_os("HDI_OUT_DIR") {
            Some(root) => PathBuf::from(root).join(name),
            None => PathBuf::from("out").join(name),
        },
    };
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    Ok(dir)
}
