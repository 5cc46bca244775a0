# `cmake --install build --prefix P`: the program, the libraries, their public headers, the docs
# and examples, and the CMake package balance_design, so that another project writes
#   find_package(balance_design CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE balance_design::core)   # or ::balance, ::optimize, ::studies
# The package finds the libraries' own dependencies with find_dependency (balance_designConfig.cmake).
include(CMakePackageConfigHelpers)

set(BD_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/balance_design)

foreach(layer core balance optimize studies)
  set_target_properties(bd_${layer} PROPERTIES EXPORT_NAME ${layer})
endforeach()
install(TARGETS bd_core bd_balance bd_optimize bd_studies
        EXPORT balance_designTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS balance-design RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

# Public headers only: not core's internals (detail/ folders, and core/integrators.hpp, which
# holds SUNDIALS' types), not the study reader's (yaml-cpp's types), the report's pages or the
# solver drivers (NLopt, Ipopt) and the solve built on them (optimize/convex_solve.hpp), which
# their own .cpp files include. tests/install_test.cmake
# checks that every installed header finds every project header it includes.
foreach(layer core balance optimize studies)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${layer}/ DESTINATION ${BD_INSTALL_INCLUDEDIR}/${layer}
          FILES_MATCHING PATTERN "*.hpp"
          PATTERN "detail" EXCLUDE
          PATTERN "integrators.hpp" EXCLUDE
          PATTERN "yaml_reader.hpp" EXCLUDE
          PATTERN "sections.hpp" EXCLUDE
          PATTERN "load_study_internal.hpp" EXCLUDE
          PATTERN "report_support.hpp" EXCLUDE
          PATTERN "pages.hpp" EXCLUDE
          PATTERN "study_parts.hpp" EXCLUDE
          PATTERN "nlopt_driver.hpp" EXCLUDE
          PATTERN "ipopt_driver.hpp" EXCLUDE
          PATTERN "convex_solve.hpp" EXCLUDE)
endforeach()

install(EXPORT balance_designTargets NAMESPACE balance_design::
        DESTINATION ${BD_INSTALL_CMAKEDIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/balance_designConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/balance_designConfig.cmake
                              INSTALL_DESTINATION ${BD_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/balance_designConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/balance_designConfig.cmake
              ${PROJECT_BINARY_DIR}/balance_designConfigVersion.cmake
        DESTINATION ${BD_INSTALL_CMAKEDIR})

# docs and examples: the notes and figures, the C++ embedding example (an outside project of
# its own), the example studies
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}
        PATTERN "*.sh" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/studies/examples/
        DESTINATION ${CMAKE_INSTALL_DOCDIR}/studies)
