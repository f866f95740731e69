# Quickstart entry points. Each target installs what is missing first.
BUILD_DIR ?= build
JOBS ?= $(shell nproc)
PORT ?= 8080

.PHONY: deps configure build python test serve bench clean

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

serve: build
	@scripts/serve-demo.sh $(BUILD_DIR) $(PORT)

bench: build
	@scripts/run-benchmarks.sh $(BUILD_DIR)

clean:
	rm -rf $(BUILD_DIR)
