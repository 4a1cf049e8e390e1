# The two commands of the README: `make run` and `make test`. Everything else is for developers.
BUILD_DIR ?= build
JOBS      ?= $(shell nproc)
DEFAULT_CASE ?= cases/daviet2016/cylinder.prm

.PHONY: run test deps build configure bench format clean

run: build
	./$(BUILD_DIR)/apps/granflow run $(DEFAULT_CASE)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE long

deps:
	@scripts/install-deps.sh

configure: deps
	@if [ ! -f $(BUILD_DIR)/build.ninja ]; then \
	  cmake -S . -B $(BUILD_DIR) -G Ninja -DCMAKE_BUILD_TYPE=Release; fi

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

bench: build
	bench/run_all.sh $(BUILD_DIR)

format:
	clang-format -i $$(git ls-files '*.cc' '*.h')

clean:
	rm -rf $(BUILD_DIR)
