fn main() {
    std::process::exit(dicephys::cli::main());
}
