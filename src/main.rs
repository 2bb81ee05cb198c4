use clap::Parser;

fn main() {
    let cli = knotrod::cli::Cli::parse();
    if let Err(e) = knotrod::cli::main_with(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
