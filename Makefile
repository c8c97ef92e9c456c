# One-command entry points; each installs missing Debian packages first and is safe to rerun.
SHELL := /bin/bash
PKG := hough_plane_detector
# make test SANITIZE=address,undefined: the same tests, built with sanitizers in their own
# workspace; the ROS tests load the instrumented nodelets into the (uninstrumented) nodelet
# manager, so the sanitizer runtime is preloaded there, leak checks stay on the gtest binaries.
SANITIZE ?=
ifeq ($(SANITIZE),)
WS := build/ws
CMAKE_ARGS := -DCMAKE_BUILD_TYPE=Release
TEST_ENV :=
else ifeq ($(SANITIZE),thread)
# make tsan builds this workspace; see the tsan target. TSAN_CONTROL=1 builds the negative
# control (test/negative_controls: the map is never locked) in its own workspace.
WS := build/ws-tsan$(if $(TSAN_CONTROL),-control)
CMAKE_ARGS := -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS=-fsanitize=thread -fno-omit-frame-pointer" \
  "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=thread" "-DCMAKE_SHARED_LINKER_FLAGS=-fsanitize=thread" \
  -DHOUGH_PLANE_DETECTOR_NEGATIVE_CONTROL=$(if $(TSAN_CONTROL),tsan)
TEST_ENV :=
else
# LEAK_CONTROL=1 (make soak-control) builds the negative control of the leak check in its own
# workspace: test/negative_controls/leaked_buffer.cpp loses a buffer when the nodelet loads.
WS := build/ws-sanitize$(if $(LEAK_CONTROL),-leak-control)
SAN := -fsanitize=$(SANITIZE)
CMAKE_ARGS := -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS=$(SAN) -fno-omit-frame-pointer -fno-sanitize-recover=undefined" \
  "-DCMAKE_EXE_LINKER_FLAGS=$(SAN)" "-DCMAKE_SHARED_LINKER_FLAGS=$(SAN)" \
  -DHOUGH_PLANE_DETECTOR_NEGATIVE_CONTROL=$(if $(LEAK_CONTROL),leak)
SAN_RUNTIMES := $(if $(findstring address,$(SANITIZE)),$(shell gcc -print-file-name=libasan.so)) \
  $(if $(findstring undefined,$(SANITIZE)),$(shell gcc -print-file-name=libubsan.so))
TEST_ENV := ASAN_OPTIONS=detect_leaks=0:verify_asan_link_order=0 UBSAN_OPTIONS=print_stacktrace=1 \
  HOUGH_PLANE_DETECTOR_HZ_ERROR=9.5 LD_PRELOAD="$(strip $(SAN_RUNTIMES))"
endif
BIN := $(WS)/devel/lib/$(PKG)
REAL_FRAMES := $(wildcard ../shared/data/kinect-real/*.pcd)
# Debian's ROS Python modules live under /usr; a pyenv python first on PATH breaks catkin.
export PATH := /usr/bin:$(PATH)

.PHONY: all help deps build test tsan tsan-control fuzz soak soak-control demo demo-offline bench evaluate tuning-check clean

all: build

help:
	@echo "make deps          install the Debian packages the build, tests and demo need (safe to rerun)"
	@echo "make build         build the catkin workspace in build/ws (Release)"
	@echo "make test          build and run every gtest, rostest, fuzz smoke run and the install-space rostest; prints N passed, N failed"
	@echo "make test SANITIZE=address,undefined   the same with sanitizers, in its own workspace"
	@echo "make tsan          ThreadSanitizer on the nodelet under concurrent clouds, reconfigure and services"
	@echo "make tsan-control  the same on a build that skips the map lock (must report races)"
	@echo "make fuzz          libFuzzer on cloud views, map files and PCD headers (FUZZ_SECONDS each)"
	@echo "make demo          simulated Kinect -> detector nodelet -> planes, no hardware"
	@echo "make demo-offline  the core alone on the simulated room, with per-frame figures"
	@echo "make bench         time per frame and accuracy against PCL RANSAC and OMPS"
	@echo "make evaluate      the paper's experiments, held-out rooms, real frames -> docs/RESULTS.md (QUICK=1: short)"
	@echo "make tuning-check  the rendered sets a detector change may be tuned on, one line each, and osd-learn (ARGS=--causes, --list, --noise-correlation PX, --PARAM VALUE)"
	@echo "make soak          10,000 frames through the core, then the nodelet (memory, ms, valgrind's leak checks)"
	@echo "make soak-control  the leak check's negative control (must report a leak)"
	@echo "make clean         remove build/"

deps:
	@scripts/install_deps.sh

# The workspace's copy of the package links every top-level entry but build/ itself: a link to
# the whole tree would make roslaunch's file search recurse through build/ws/src forever.
build: deps
	@if [ -L $(WS)/src/$(PKG) ]; then rm $(WS)/src/$(PKG); fi
	@mkdir -p $(WS)/src/$(PKG)
	@for f in $$(ls -A | grep -vxE 'build|\.git'); do ln -sfn $(CURDIR)/$$f $(WS)/src/$(PKG)/$$f; done
	catkin_make -C $(WS) $(CMAKE_ARGS)

test: build
	@rm -rf $(WS)/build/test_results
	@catkin_make -C $(WS) tests > $(WS)/build_tests.log 2>&1 || { tail -30 $(WS)/build_tests.log; false; }
	@$(TEST_ENV) catkin_make -C $(WS) run_tests > $(WS)/run_tests.log 2>&1 || true
	@grep -E "^\[ *(RUN|OK|FAILED|PASSED) *\]|Failure|error:|runtime error|ERROR: AddressSanitizer" $(WS)/run_tests.log | grep -v "^\[ *RUN" || true
	@if [ -n "$(SANITIZE)" ]; then scripts/run_sanitized_gtests.sh $(CURDIR)/$(WS); fi
	@if [ -z "$(SANITIZE)" ]; then scripts/run_fuzzers.sh smoke $(CURDIR)/$(WS)/build/test_results/fuzz || true; fi
	@if [ -z "$(SANITIZE)" ]; then scripts/test_install_space.sh $(CURDIR)/$(WS) $(CURDIR)/$(WS)/build/test_results/install_space || true; fi
	@scripts/test_summary.py $(WS)/build/test_results

# ThreadSanitizer over the running nodelet: test/concurrency.test (clouds, reconfigure and
# service calls at once) with the instrumented nodelets in a manager that preloads the runtime;
# any report in the manager fails the target (scripts/tsan.supp lists what is suppressed in
# ROS's uninstrumented libraries, and why). make tsan-control proves the run can fail: the
# same run on a build whose save_map skips the map lock must be reported.
TSAN_SECONDS ?= 30
tsan:
	@$(MAKE) --no-print-directory build SANITIZE=thread
	@scripts/run_tsan.sh $(CURDIR)/build/ws-tsan $(TSAN_SECONDS) clean

tsan-control:
	@$(MAKE) --no-print-directory build SANITIZE=thread TSAN_CONTROL=1
	@scripts/run_tsan.sh $(CURDIR)/build/ws-tsan-control $(TSAN_SECONDS) reported

# libFuzzer on the cloud conversion and the map loader, FUZZ_SECONDS per target.
FUZZ_SECONDS ?= 300
fuzz: deps
	scripts/run_fuzzers.sh long $(FUZZ_SECONDS)

# The whole ROS path for about 20 s (simulated Kinect -> detector nodelet), then the map against
# the truth and a picture; roslaunch starts its own master when none runs.
demo: build
	@scripts/run_demo.sh $(CURDIR)/$(WS) 20 $(CURDIR)/build/demo.png

# The core alone on the same simulated room, with per-frame figures.
demo-offline: build
	$(BIN)/hough_demo

bench: build
	$(BIN)/benchmark_detector $(REAL_FRAMES)

# The paper's experiments (Fig. 6, 7, 8, Table 3, timing) with PCL's methods on the same frames:
# docs/RESULTS.md and docs/results/*.png; QUICK=1 is a short run into build/evaluate-quick.
QUICK ?=
EVALUATE_DIR := $(if $(QUICK),build/evaluate-quick,docs)
evaluate: build
	@scripts/install_deps.sh gnuplot-nox
	@scripts/evaluate.sh $(BIN) $(EVALUATE_DIR) $(if $(QUICK),1,0) $(REAL_FRAMES)

# While changing the detector: the sets it may be tuned on (no held-out seeds), a minute or two.
OSD_LEARN := ../shared/data/osd-learn
tuning-check: build
	$(BIN)/tuning_check $(if $(wildcard $(OSD_LEARN)/annotations.json),--osd $(OSD_LEARN)) $(ARGS)

# 10,000 simulated frames through one detector (the core) and then through the nodelet in a
# manager: resident memory, chunks, planes, ms; valgrind's leak check over short runs of both.
# make soak SANITIZE=address: the core soak under AddressSanitizer (LeakSanitizer at its exit)
# and the nodelet's short run under LeakSanitizer instead of valgrind.
SOAK_FRAMES ?= 10000
SOAK_VALGRIND_FRAMES ?= 150
soak: build
	@scripts/install_deps.sh valgrind
	$(BIN)/soak_detector $(if $(SANITIZE),$(SOAK_VALGRIND_FRAMES),$(SOAK_FRAMES))
	@[ -z "$(SANITIZE)" ] && command -v valgrind > /dev/null && valgrind --leak-check=full --errors-for-leak-kinds=definite \
	  --error-exitcode=3 $(BIN)/soak_detector 60 2>&1 | grep -E "definitely lost|no leaks are possible|ERROR SUMMARY" || true
	@scripts/soak_nodelet.sh $(CURDIR)/$(WS) $(SOAK_FRAMES) $(SOAK_VALGRIND_FRAMES)

# Proves the nodelet's LeakSanitizer run can fail: a build whose nodelet library loses a buffer
# when it loads (test/negative_controls) must have leak records through this package's code.
soak-control:
	@$(MAKE) --no-print-directory build SANITIZE=address LEAK_CONTROL=1
	@LEAK_EXPECTED=1 scripts/soak_nodelet.sh $(CURDIR)/build/ws-sanitize-leak-control 0 $(SOAK_VALGRIND_FRAMES)

clean:
	rm -rf build
