# penumbra_add_plugin(NAME KIND SOURCES src... [ALIASES alias...] [LIBRARIES lib...])
# Builds penumbra-<KIND>-<NAME>.so into PENUMBRA_PLUGIN_OUTPUT_DIRECTORY. An alias becomes a symbolic
# link penumbra-<KIND>-<ALIAS>.so, so the loader finds it by file name without opening other plugins.
#
# The same file serves Penumbra's own tree and plugin authors using the installed SDK
# (find_package(Penumbra), see PenumbraConfig.cmake). Its callers set:
#   PENUMBRA_CORE_TARGET              target to link (penumbra-core in the tree, Penumbra::core outside)
#   PENUMBRA_PLUGIN_OUTPUT_DIRECTORY  where the .so files go (outside: <build>/plugins by default)
#   PENUMBRA_PLUGIN_INSTALL_DIR       if set, `cmake --install` copies the plugin (and its aliases) there
#
# Plugins are compiled with hidden visibility: only the entry point written by PENUMBRA_PLUGIN is
# exported, so two plugins may define the same internal names without clashing.
function(penumbra_add_plugin NAME KIND)
  cmake_parse_arguments(ARG "" "" "SOURCES;ALIASES;LIBRARIES" ${ARGN})
  if(NOT KIND MATCHES "^(integrator|sampler|bsdf|light|texture)$")
    message(FATAL_ERROR "penumbra_add_plugin(${NAME} ${KIND}): KIND must be integrator, sampler, bsdf, light or texture")
  endif()
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "penumbra_add_plugin(${NAME} ${KIND}): no SOURCES")
  endif()
  set(target penumbra-${KIND}-${NAME})
  # One RUNPATH for the build and the install tree (BUILD_WITH_INSTALL_RPATH): a build RUNPATH that
  # `cmake --install` rewrites is padded with ':', and an empty entry searches the current folder.
  # In Penumbra's tree the core is two folders up from the plugins in both trees; outside it the
  # core's absolute folder is added, as the plugin's build folder has no core beside it.
  set(_rpath "$ORIGIN/../..")
  if(NOT PENUMBRA_CORE_TARGET STREQUAL "penumbra-core")
    get_target_property(_core_file ${PENUMBRA_CORE_TARGET} LOCATION)
    get_filename_component(_core_dir "${_core_file}" DIRECTORY)
    list(APPEND _rpath "${_core_dir}")
  endif()
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE ${PENUMBRA_CORE_TARGET} ${ARG_LIBRARIES})
  target_compile_features(${target} PRIVATE cxx_std_20)
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    LIBRARY_OUTPUT_DIRECTORY ${PENUMBRA_PLUGIN_OUTPUT_DIRECTORY}
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    INSTALL_RPATH "${_rpath}"
    BUILD_WITH_INSTALL_RPATH ON)
  foreach(alias IN LISTS ARG_ALIASES)
    add_custom_command(TARGET ${target} POST_BUILD
      COMMAND ${CMAKE_COMMAND} -E create_symlink ${target}.so
              ${PENUMBRA_PLUGIN_OUTPUT_DIRECTORY}/penumbra-${KIND}-${alias}.so)
  endforeach()
  if(PENUMBRA_PLUGIN_INSTALL_DIR)
    install(TARGETS ${target} LIBRARY DESTINATION ${PENUMBRA_PLUGIN_INSTALL_DIR})
    foreach(alias IN LISTS ARG_ALIASES)
      install(CODE "file(CREATE_LINK ${target}.so
        \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/${PENUMBRA_PLUGIN_INSTALL_DIR}/penumbra-${KIND}-${alias}.so\" SYMBOLIC)")
    endforeach()
  endif()
  set_property(GLOBAL APPEND PROPERTY PENUMBRA_PLUGIN_TARGETS ${target})
endfunction()
