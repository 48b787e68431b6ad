# `cmake --install build --prefix P`: the vobench command and the files it reads at run time.
#   P/bin/vobench
#   P/share/vobench/scenes/       MJCF scenes and the built-in scenarios (vobench run l_hallway)
#   P/share/vobench/suites/       the committed suites (results/baseline.json names suites/ci.yaml)
#   P/share/vobench/harness/plots/*.py  the plot scripts
#   P/share/vobench/results/baseline.json   the default baseline of `vobench check`
# share/vobench has the source tree's layout, so sim::DataDir() (sim/data_dir.h) is the one
# lookup for both: the installed vobench finds it from its own path (bin/../share/vobench).
# (vo::vo's headers, library and CMake package are installed by vo/CMakeLists.txt.)
include(GNUInstallDirs)
set(VOBENCH_DATA_DESTINATION ${CMAKE_INSTALL_DATADIR}/vobench)
install(TARGETS vobench RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION ${VOBENCH_DATA_DESTINATION}/scenes)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/suites/ DESTINATION ${VOBENCH_DATA_DESTINATION}/suites)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/harness/plots/
  DESTINATION ${VOBENCH_DATA_DESTINATION}/harness/plots
  FILES_MATCHING PATTERN "*.py" PATTERN "__pycache__" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/results/baseline.json
  DESTINATION ${VOBENCH_DATA_DESTINATION}/results)
