# penumbra_add_plugin(NAME KIND SOURCES src... [ALIASES alias...] [LIBRARIES lib...])
# Builds penumbra-<KIND>-<NAME>.so into the plugin folder. An alias becomes a symbolic link
# penumbra-<KIND>-<ALIAS>.so, so the loader finds it by file name without opening other plugins.
function(penumbra_add_plugin NAME KIND)
  cmake_parse_arguments(ARG "" "" "SOURCES;ALIASES;LIBRARIES" ${ARGN})
  set(target penumbra-${KIND}-${NAME})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE penumbra-core ${ARG_LIBRARIES})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    LIBRARY_OUTPUT_DIRECTORY ${PENUMBRA_PLUGIN_OUTPUT_DIRECTORY}
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    BUILD_RPATH "$ORIGIN/../.."
    INSTALL_RPATH "$ORIGIN/../..")
  foreach(alias IN LISTS ARG_ALIASES)
    add_custom_command(TARGET ${target} POST_BUILD
      COMMAND ${CMAKE_COMMAND} -E create_symlink ${target}.so
              ${PENUMBRA_PLUGIN_OUTPUT_DIRECTORY}/penumbra-${KIND}-${alias}.so)
  endforeach()
  set_property(GLOBAL APPEND PROPERTY PENUMBRA_PLUGIN_TARGETS ${target})
endfunction()
