# flexure_write_if_changed(FILE TEXT): writes TEXT to FILE unless it holds it already, so that
# what depends on a generated file is rebuilt only when it changes (cmake -P scripts).
function(flexure_write_if_changed file text)
  set(old "")
  if(EXISTS "${file}")
    file(READ "${file}" old)
  endif()
  if(NOT old STREQUAL text)
    file(WRITE "${file}" "${text}")
  endif()
endfunction()
