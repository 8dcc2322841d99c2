fn main() {
    std::process::exit(pbrs::cli::main());
}
