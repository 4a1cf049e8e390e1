# The two commands of the README: `make run` and `make test`. Everything else is for developers.
BUILD_DIR ?= build
# The unit tests are also built against deal.II's debug library (libdeal.ii.g.so, with its
# assertions): the release library silently accepts misuse such as a quad-only element on triangles.
DEBUG_BUILD_DIR ?= build-debug
JOBS      ?= $(shell nproc)
DEFAULT_CASE ?= cases/daviet2016/cylinder.prm

.PHONY: run test test-debug deps build build-debug configure configure-debug bench format clean

run: build
	./$(BUILD_DIR)/apps/granflow run $(DEFAULT_CASE)

test: build test-debug
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE long

test-debug: build-debug
	cd $(DEBUG_BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L unit

deps:
	@scripts/install-deps.sh

configure: deps
	@if [ ! -f $(BUILD_DIR)/build.ninja ]; then \
	  cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release; fi

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

configure-debug: deps
	@if [ ! -f $(DEBUG_BUILD_DIR)/build.ninja ]; then \
	  cmake -S . -B $(DEBUG_BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Debug -DGRANFLOW_BENCHMARKS=OFF; fi

# Only the unit tests run there (test-debug), so only they are built.
build-debug: configure-debug
	cmake --build $(DEBUG_BUILD_DIR) -j $(JOBS) --target unit_tests

bench: build
	bench/run_all.sh $(BUILD_DIR)

format:
	clang-format -i $$(git ls-files '*.cc' '*.h')

clean:
	rm -rf $(BUILD_DIR) $(DEBUG_BUILD_DIR)
