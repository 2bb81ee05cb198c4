// Bakes in hashes of the sources (src/io/source_hash.rs): the one of the
// sources that compute results keys the map's cache of lines (a rebuilt
// binary never resumes lines from another build's solver), the one of all
// sources lets the binary tell at run time whether its checkout is what it
// was built from (io::build_info). Nothing here reads git: a commit changes
// no source, so it rebuilds nothing.
#[path = "src/io/source_hash.rs"]
mod source_hash;

fn main() {
    let hashes = source_hash::source_hashes(std::path::Path::new("src"));
    println!(
        "cargo:rustc-env=KNOTROD_SOURCE_HASH={:016x}",
        hashes.results
    );
    println!(
        "cargo:rustc-env=KNOTROD_ALL_SOURCES_HASH={:016x}",
        hashes.all
    );
    // a folder is scanned whole: any file added, removed or edited reruns this
    println!("cargo:rerun-if-changed=src");
}
