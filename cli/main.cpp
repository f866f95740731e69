// The solidtex executable: one binary, several subcommands. Errors are reported here, once.
#include <tbb/global_control.h>

#include <exception>
#include <iostream>
#include <memory>

#include "commands.h"

namespace solidtex::cli {

namespace {
std::unique_ptr<tbb::global_control> g_threads;
}

void set_thread_limit(int threads) {
  if (threads > 0) g_threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

}  // namespace solidtex::cli

namespace {

constexpr const char* kUsage =
    "usage: solidtex <command> [options]\n"
    "commands:\n"
    "  analyze IMAGE [--yz IMAGE --zx IMAGE] [--mask IMAGE [--mask-yz IMAGE --mask-zx IMAGE]]\n"
    "          [--mask-weight 1] [--levels auto|L] [--neighborhood 9]\n"
    "          [--candidates 12] [--pca-dims 20] [--seed S] [--threads T] [--grain auto|none|x|y|crossed]\n"
    "          [--search-k 24] [--knn-checks 192] [--balance-rounds 3] [--balance-box 24]\n"
    "          [--balance-strength 0.025] [--balance-fine-gain 2]\n"
    "          -o TABLE.stx [--json]\n"
    "  slice TABLE.stx (--axis x|y|z --at K [--origin U,V] | --plane OX,OY,OZ,UX,UY,UZ,VX,VY,VZ\n"
    "          [--resample auto|nearest|cubic])\n"
    "          --size W,H [--scheme plain|subpass|grid|dual-grid] [--field identity|quat:W,X,Y,Z|axis:X,Y,Z,DEG|FILE]\n"
    "          [--seed S] [--threads T] [--typicality auto|T] [--finest-typicality-scale 0.7] [--balance 1]\n"
    "          [--init auto|scatter|slab] [--init-band 8] [--color auto|vote|medoid|mean]\n"
    "          [--finest-match auto|triple|plane] [--finest-sources cross|square]\n"
    "          [--passes 1] [--coarse-passes 3] [--cell 12] [--matcher paper|coherent]\n"
    "          [--plane-weights XY,YZ,ZX] [--cache-mb 256] [--region-table B.stx --regions LABEL]\n"
    "          [--finest-subpass-size 1|2] [--stats STATS.json] [--reference REF.png] [--energy] -o OUT.png\n"
    "  field SKETCH.json -o FIELD.stf [--json]\n"
    "  serve [--host 127.0.0.1] [--port 8080] [--data DIR] [--threads 2] [--io-threads 2] [--queue 16]\n"
    "          [--deadline 30] [--max-deadline 300] [--cache-mb M] [--max-upload-mb M] [--max-image-side PX]\n"
    "          [--max-image-pixels N] [--max-voxels N] [--max-field-nodes N] [--max-mesh-vertices N]\n"
    "          [--max-mesh-faces N] [--max-jobs 4] [--analysis-threads 1]\n"
    "          [--max-request-mb 1536] [--volume-state-mb 512] [--idle-evict-s 300] [--array-extent 1024]\n"
    "          [--chunk-cache-mb 64] [--web-root DIR] [--job-lease-seconds 30]\n"
    "          [--storage s3://BUCKET/PREFIX --s3-endpoint URL]\n"
    "          --volume-state-mb bounds loaded volumes' tables, fields, bands and synthesizers (LRU\n"
    "          eviction); --idle-evict-s evicts volumes idle that long (0: never); --array-extent is\n"
    "          the side of the /zarr and /zarr2 arrays in finest voxels, --chunk-cache-mb keeps\n"
    "          their encoded chunks for repeated reads; --web-root is the browser app served at /\n"
    "          (default: the source tree's web/); --job-lease-seconds is how long an analysis job\n"
    "          stays claimed without renewal before another replica on the same --data takes it\n"
    "          over; see README limits and \"Several replicas on one data directory\"; --storage\n"
    "          keeps the data in an S3-compatible store instead of --data (credentials from\n"
    "          AWS_ACCESS_KEY_ID, AWS_SECRET_ACCESS_KEY, AWS_REGION; README \"Storage backends\")\n"
    "  exemplar KIND -o FILE.png [--size W,H] [--seed S]     KIND: wood, stripes, bricks, noise, spots, pebbles\n";

}  // namespace

int main(int argc, char** argv) {
  using namespace solidtex;
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  try {
    Status st;
    if (command == "analyze") st = cli::run_analyze(args);
    else if (command == "exemplar") st = cli::run_exemplar(args);
    else if (command == "slice") st = cli::run_slice(args);
    else if (command == "field") st = cli::run_field(args);
    else if (command == "serve") st = cli::run_serve(args);
    else st = Status(StatusCode::kInvalidArgument, "unknown command '" + command + "'\n" + kUsage, "command");
    if (!st.is_ok()) {
      std::cerr << "solidtex " << command << ": error: " << st.to_string() << "\n";
      return st.code() == StatusCode::kInvalidArgument ? 2 : 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "solidtex " << command << ": internal error: " << e.what() << "\n";
    return 1;
  }
}
