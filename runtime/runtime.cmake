# qdot_runtime: the SUNDIALS IDA session (ida/), the ARKODE session (arkode/), the simulation loop and run options (sim/) and the
# result writers (output/). Included by runtime/CMakeLists.txt, which globs RUNTIME_SOURCES.
# Links SUNDIALS 6.4 (Debian's shared libraries) with the dense and KLU direct linear solvers.
find_package(SUNDIALS REQUIRED CONFIG)
find_package(Threads REQUIRED)  # sim/TieredModel: the JIT compiles on a background thread
find_package(Eigen3 3.4 REQUIRED NO_MODULE)  # ida/DummyDerivatives: small dense QR (header-only)

# ida/ReducedKlu calls KLU itself (the reduced Newton matrix), not only through SUNDIALS' solver.
find_library(QDOT_KLU_LIBRARY NAMES klu REQUIRED)

add_library(qdot_runtime STATIC ${RUNTIME_SOURCES})
target_include_directories(qdot_runtime PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include ${CMAKE_CURRENT_SOURCE_DIR})
target_link_libraries(qdot_runtime
  PUBLIC fmt::fmt CLI11::CLI11 Threads::Threads
  PRIVATE Eigen3::Eigen SUNDIALS::ida_shared SUNDIALS::arkode_shared SUNDIALS::nvecserial_shared SUNDIALS::sunmatrixdense_shared
          SUNDIALS::sunmatrixsparse_shared SUNDIALS::sunlinsoldense_shared SUNDIALS::sunlinsolklu_shared
          ${QDOT_KLU_LIBRARY})

# qdot_exe_main: the main of standalone model executables (exe/, `qdot build`). qdot links it,
# with qdot_runtime, qdot_vm and the shared SUNDIALS and fmt libraries, to a generated source file
# holding the model (exe/Embedded.h); the paths are compiled into qdot (compiler/driver).
file(GLOB EXE_MAIN_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/exe/*.cpp)
if(EXE_MAIN_SOURCES)
  add_library(qdot_exe_main STATIC ${EXE_MAIN_SOURCES})
  target_link_libraries(qdot_exe_main PUBLIC qdot_runtime qdot_vm)
endif()
