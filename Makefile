# Quickstart entry points. Each target installs what is missing first.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
PORT ?= 8080
# Hardening trees (see "Fuzzing and sanitizers" below).
FUZZ_DIR ?= build-fuzz
ASAN_DIR ?= build-asan
FUZZ_SECONDS ?= 120       # per harness, make fuzz
FUZZ_TEST_SECONDS ?= 10   # per harness, a short run at the end of make test (0: none; see fuzz/README.md)

.PHONY: deps configure build python test serve bench clean fuzz fuzz-build test-sanitize

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

python: deps
	@scripts/setup-python.sh $(abspath $(BUILD_DIR))

test: build python
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)
ifneq ($(strip $(FUZZ_TEST_SECONDS)),0)
	@$(build_fuzz_tree)
	@scripts/run-fuzz.sh $(FUZZ_DIR) $(strip $(FUZZ_TEST_SECONDS))
endif

serve: build
	@scripts/serve-demo.sh $(BUILD_DIR) $(PORT)

bench: build
	@scripts/run-benchmarks.sh $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR)

# ---- Cluster (issue #16; deploy/README.md) -------------------------------------------------
# make cluster: 3 replicas on one store behind nginx on 127.0.0.1:CLUSTER_PORT until Ctrl-C.
# make cluster-test: tests/cluster against such a cluster, then the S3 backend's own tests
# (tests/python/test_s3_storage.py, which make test skips until versitygw is built); not part
# of make test.
CLUSTER_PORT ?= 8090
.PHONY: cluster cluster-test
cluster: build
	@scripts/cluster.sh deps
	@CLUSTER_PORT=$(CLUSTER_PORT) scripts/cluster.sh up
cluster-test: build python
	@scripts/cluster.sh deps
	@SOLIDTEX_BIN=$(abspath $(BUILD_DIR))/bin/solidtex $(BUILD_DIR)/venv/bin/python -m pytest -q -p no:cacheprovider tests/cluster
	@scripts/versitygw.sh build >/dev/null
	@SOLIDTEX_BIN=$(abspath $(BUILD_DIR))/bin/solidtex $(BUILD_DIR)/venv/bin/python -m pytest -q -p no:cacheprovider tests/python/test_s3_storage.py

# ---- Fuzzing and sanitizers -----------------------------------------------------------------
# The fuzz tree: clang 14, every target instrumented for libFuzzer with ASan and UBSan
# (-DSOLIDTEX_FUZZ=ON); only the harnesses of fuzz/ and the libraries they link are built.
define build_fuzz_tree
cmake -S . -B $(FUZZ_DIR) -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 -DSOLIDTEX_FUZZ=ON \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null && cmake --build $(FUZZ_DIR) --target fuzzers -j $(JOBS)
endef

fuzz-build: deps
	@$(build_fuzz_tree)

# Every harness for FUZZ_SECONDS (make fuzz FUZZ_SECONDS=600); fails on any crash, leak,
# timeout or out-of-memory input (saved under $(FUZZ_DIR)/artifacts/<harness>/).
fuzz: fuzz-build
	@scripts/run-fuzz.sh $(FUZZ_DIR) $(strip $(FUZZ_SECONDS))

# The unit tests, CLI checks and Python service tests against an ASan + UBSan build (gcc).
# Sanitizer reports of every process (tests, CLI, the server the Python tests start) are
# written to $(ASAN_DIR)/sanitizer-logs/; any report fails the target and is printed.
#  - LeakSanitizer ignores string buffers allocated in std::string::_M_assign that nothing
#    owns: OpenImageIO 2.4's PNG reader leaks its error message on every truncated PNG
#    (png_error longjmps past the destructor). A leaked object holding a string is still
#    reported (as the object).
#  - The Python tests run the server through $(ASAN_DIR)/solidtex-sanitized, which gives
#    `serve` a 300 s default request deadline unless the test sets one: sanitized synthesis
#    is several times slower than the 30 s default allows.
SANITIZER_LOGS = $(abspath $(ASAN_DIR))/sanitizer-logs
test-sanitize: deps
	@cmake -S . -B $(ASAN_DIR) -G Ninja -DSOLIDTEX_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
	@cmake --build $(ASAN_DIR) -j $(JOBS)
	@scripts/setup-python.sh $(abspath $(ASAN_DIR))
	@rm -rf $(SANITIZER_LOGS) && mkdir -p $(SANITIZER_LOGS)
	@printf 'leak:std::__cxx11::basic_string<char, std::char_traits<char>, std::allocator<char> >::_M_assign\n' \
	  > $(ASAN_DIR)/lsan.supp
	@printf '%s\n' '#!/bin/sh' 'bin=$(abspath $(ASAN_DIR))/bin/solidtex' \
	  'case " $$* " in *" --deadline "*|*" --max-deadline "*) exec "$$bin" "$$@";; esac' \
	  'if [ "$$1" = serve ]; then shift; exec "$$bin" serve --deadline 300 "$$@"; fi' 'exec "$$bin" "$$@"' \
	  > $(ASAN_DIR)/solidtex-sanitized && chmod +x $(ASAN_DIR)/solidtex-sanitized
	@export ASAN_OPTIONS=log_path=$(SANITIZER_LOGS)/asan:detect_leaks=1:check_initialization_order=1 \
	  LSAN_OPTIONS=suppressions=$(abspath $(ASAN_DIR))/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=log_path=$(SANITIZER_LOGS)/ubsan:print_stacktrace=1; \
	  (cd $(ASAN_DIR) && ctest --output-on-failure -j $(JOBS) -E '^python\.service$$'); rc=$$?; \
	  SOLIDTEX_BIN=$(abspath $(ASAN_DIR))/solidtex-sanitized \
	    $(ASAN_DIR)/venv/bin/python -m pytest -q -p no:cacheprovider tests/python || rc=1; \
	  if [ -n "$$(ls $(SANITIZER_LOGS))" ]; then \
	    for f in $(SANITIZER_LOGS)/*; do echo "==== $$f"; cat "$$f"; done; \
	    echo "test-sanitize: sanitizer reports in $(SANITIZER_LOGS)" >&2; exit 1; \
	  fi; \
	  if [ $$rc -ne 0 ]; then echo "test-sanitize: tests failed" >&2; fi; exit $$rc
