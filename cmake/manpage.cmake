# cmake -DFLEXURE=.../flexure -DOUT=.../flexure.1 [-DGZIP=/usr/bin/gzip] -P manpage.cmake
# Writes the man page flexure(1) from the executable's own help: `flexure --help` (name,
# synopsis, global options, exit status) and `flexure COMMAND --help` for every command that
# lists (one subsection each, with its arguments and options), so the page says what the
# binary does. Run after every link of flexure (cmake/install.cmake). The page is rewritten only
# when its text changes; with GZIP, OUT.gz (gzip -9n: no name, no time, reproducible) is written
# beside it, with flexure-draw.1.gz a link to it (flexure-draw takes the same command line).
cmake_minimum_required(VERSION 3.18)
foreach(var FLEXURE OUT)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "manpage.cmake: -D${var}=... is needed")
  endif()
endforeach()

# The help text of `flexure ARGS... --help`, as a list of lines in which ';', '[' and ']' are
# kept as @S@, @L@ and @R@ (CMake lists split on ';' only outside brackets).
function(help_lines out)
  execute_process(COMMAND "${FLEXURE}" ${ARGN} --help OUTPUT_VARIABLE text ERROR_VARIABLE err RESULT_VARIABLE rc)
  string(STRIP "${err}" err)
  if(NOT rc EQUAL 0 OR text STREQUAL "")
    string(REPLACE ";" " " args "${ARGN}")
    message(FATAL_ERROR "manpage.cmake: '${FLEXURE} ${args} --help' exited with ${rc} (${err}): the man page needs its help")
  endif()
  string(REPLACE ";" "@S@" text "${text}")
  string(REPLACE "[" "@L@" text "${text}")
  string(REPLACE "]" "@R@" text "${text}")
  string(REPLACE "\n" ";" text "${text}")
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# One line of help as troff text: brackets and semicolons back, backslashes as \e, every '-' a
# minus (\-, so that options copy as typed), a control character at the start escaped.
function(troff out line)
  string(REPLACE "\\" "\\e" line "${line}")
  string(REPLACE "-" "\\-" line "${line}")
  string(REPLACE "@S@" ";" line "${line}")
  string(REPLACE "@L@" "[" line "${line}")
  string(REPLACE "@R@" "]" line "${line}")
  if(line MATCHES "^[.']")
    set(line "\\&${line}")
  endif()
  set(${out} "${line}" PARENT_SCOPE)
endfunction()

# An entry's name as CLI11 prints it ("-o,--output FILE", "--set KEY=VALUE ...", "SCENE ...")
# in troff: the flags bold, what follows them italic.
function(troff_entry out name)
  troff(name "${name}")
  if(name MATCHES "^(\\\\-[^ ]*)( (.*))?$")
    set(flags "${CMAKE_MATCH_1}")
    set(rest "${CMAKE_MATCH_3}")
    string(REPLACE "," "\\fR, \\fB" flags "${flags}")
    set(text "\\fB${flags}\\fR")
    if(NOT rest STREQUAL "")
      string(APPEND text " \\fI${rest}\\fR")
    endif()
  else()
    set(text "\\fI${name}\\fR")
  endif()
  set(${out} "${text}" PARENT_SCOPE)
endfunction()

# Parses one help text. Sets, in the caller: <p>_first (the line before "Usage:"), <p>_usage,
# <p>_commands (the names under "Subcommands:"), <p>_footer (the lines after the last list,
# troff) and <p>_lists (troff: a paragraph title per list, a .TP per entry; "-h,--help" left
# out when SKIP_HELP is given).
function(parse_help p lines)
  set(skip_help OFF)
  if("SKIP_HELP" IN_LIST ARGN)
    set(skip_help ON)
  endif()
  set(first "")
  set(usage "")
  set(commands "")
  set(footer "")
  set(lists "")
  set(section "")
  set(title "")
  foreach(line IN LISTS lines)
    string(REGEX REPLACE " +$" "" line "${line}")
    if(line STREQUAL "")
      if(NOT section STREQUAL "footer")
        set(section "")
      endif()
    elseif(line MATCHES "^Usage: (.*)$")
      set(usage "${CMAKE_MATCH_1}")
    elseif(line MATCHES "^(Positionals|Options|Subcommands):$")
      set(section "${CMAKE_MATCH_1}")
      set(title ".PP\n\\fI${section}:\\fR\n")  # written before the list's first entry
    elseif(line MATCHES "^  ([^ ]+( [^ ]+)*)(  +(.*))?$" AND NOT section STREQUAL "" AND NOT section STREQUAL "footer")
      set(name "${CMAKE_MATCH_1}")
      set(what "${CMAKE_MATCH_4}")
      if(section STREQUAL "Subcommands")
        list(APPEND commands "${name}")
      elseif(NOT (skip_help AND name STREQUAL "-h,--help"))
        troff_entry(name "${name}")
        troff(what "${what}")
        string(APPEND lists "${title}.TP\n${name}\n${what}\n")
        set(title "")
      endif()
    elseif(line MATCHES "^    +(.*)$" AND NOT section STREQUAL "" AND NOT section STREQUAL "footer")
      # A description continued on the next line (a long name, or a description with newlines).
      if(NOT section STREQUAL "Subcommands")
        troff(what "${CMAKE_MATCH_1}")
        string(APPEND lists "${what}\n")
      endif()
    elseif(usage STREQUAL "")
      set(first "${line}")
    else()
      set(section "footer")
      troff(line "${line}")
      string(APPEND footer "${line}\n")
    endif()
  endforeach()
  if(usage STREQUAL "")
    message(FATAL_ERROR "manpage.cmake: no 'Usage:' line in the help of ${FLEXURE} (${p})")
  endif()
  foreach(var first usage commands footer lists)
    set(${p}_${var} "${${var}}" PARENT_SCOPE)
  endforeach()
endfunction()

help_lines(lines)
parse_help(top "${lines}")
if(NOT top_first MATCHES "^flexure ([^ ]+) - (.+)$")
  message(FATAL_ERROR "manpage.cmake: 'flexure --help' does not start with 'flexure VERSION - WHAT': ${top_first}")
endif()
set(version "${CMAKE_MATCH_1}")
troff(summary "${CMAKE_MATCH_2}")
if(top_commands STREQUAL "")
  message(FATAL_ERROR "manpage.cmake: 'flexure --help' lists no subcommands")
endif()
troff(synopsis "${top_usage}")
string(REGEX REPLACE "^flexure " "" synopsis "${synopsis}")
# The exit status paragraph of the help ("Exit status: 0 success, ..."), its own section.
set(exit_status "")
set(notes "${top_footer}")
if(top_footer MATCHES "^Exit status: (.*)$")
  set(exit_status "${CMAKE_MATCH_1}")
  set(notes "")
endif()
string(REPLACE ";" "\\fR, \\fB" command_list "${top_commands}")
# The global options are the section itself: no paragraph title.
string(REPLACE ".PP\n\\fIOptions:\\fR\n" "" top_options "${top_lists}")

set(page ".\\\" The man page of flexure ${version}, generated from its --help by cmake/manpage.cmake: do not edit.
.TH FLEXURE 1 \"\" \"flexure ${version}\" \"User Commands\"
.nh
.ad l
.SH NAME
flexure, flexure\\-draw \\- ${summary}
.SH SYNOPSIS
.B flexure
${synopsis}
.br
.B flexure
\\fICOMMAND\\fR \\fB\\-\\-help\\fR
.SH DESCRIPTION
flexure tells whether a geometric constraint system is rigid, and follows its continuous motions:
it analyses a scene (a TOML scene file, a catalog name, a path JSON or a file in another format)
at its start configuration, tracks its deformation path and draws it.
The commands are \\fB${command_list}\\fR; each is described below with its own options, as
\\fBflexure \\fICOMMAND\\fB \\-\\-help\\fR prints them.
.PP
\\fBflexure\\-draw\\fR takes the same command line. \\fBflexure\\fR runs the commands that draw
nothing itself and hands the commands that draw (pictures, animations, the viewer) to the
\\fBflexure\\-draw\\fR in its own folder, unchanged, in the same process.
${notes}.SH OPTIONS
${top_options}.SH COMMANDS
")
foreach(command IN LISTS top_commands)
  help_lines(lines ${command})
  parse_help(cmd "${lines}" SKIP_HELP)
  troff(usage "${cmd_usage}")
  troff(first "${cmd_first}")
  string(REGEX REPLACE "^flexure [^ ]+ ?" "" usage_rest "${usage}")
  string(APPEND page ".SS ${command}\n.B flexure ${command}\n${usage_rest}\n.PP\n${first}\n${cmd_lists}")
  if(NOT cmd_footer STREQUAL top_footer)
    string(APPEND page ".PP\n${cmd_footer}")
  endif()
endforeach()
if(NOT exit_status STREQUAL "")
  string(APPEND page ".SH \"EXIT STATUS\"\n${exit_status}\n")
endif()
string(APPEND page ".SH ENVIRONMENT
.TP
.B FLEXURE_AV_MODULE
the absolute path of \\fIlibflexure\\-av.so\\fR, the only place it is then loaded from (a relative path
is refused). Unset, it is loaded from beside the executable's real file or from
\\fIPREFIX/lib/flexure\\fR (see FILES), never from the working directory.
.TP
.B FLEXURE_FONT
the font of labels and captions: a font file, or a name that fontconfig finds (default DejaVu Sans).
.TP
.B SOURCE_DATE_EPOCH
when set, the creation date of PDF files (seconds since 1970\\-01\\-01, a nonnegative integer; any
other value is refused), so that they are the same bytes on every run.
.SH FILES
.TP
.I bin/flexure\\-draw
beside \\fBflexure\\fR: the commands that draw.
.TP
.I lib/flexure/libflexure\\-av.so
beside the \\fIbin\\fR folder (or in the executables' own folder, symbolic links resolved): MP4
writing and video decoding (FFmpeg's libraries), loaded when an MP4 is written.
.SH \"SEE ALSO\"
The user guide, \\fIshare/doc/flexure/docs/user\\-guide.md\\fR under the installation prefix
(\\fI/usr\\fR for the Debian package): every command, option and output; the scene keys in
\\fIdocs/scene\\-format.md\\fR (also \\fBflexure keys\\fR); the Python module in
\\fIdocs/python.md\\fR.
")

include("${CMAKE_CURRENT_LIST_DIR}/write_if_changed.cmake")
flexure_write_if_changed("${OUT}" "${page}")
if(GZIP)
  get_filename_component(dir "${OUT}" DIRECTORY)
  if(NOT EXISTS "${OUT}.gz" OR "${OUT}" IS_NEWER_THAN "${OUT}.gz")
    execute_process(COMMAND "${GZIP}" -9 -n -c "${OUT}" OUTPUT_FILE "${OUT}.gz.tmp" RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      message(FATAL_ERROR "manpage.cmake: ${GZIP} could not compress ${OUT}")
    endif()
    file(RENAME "${OUT}.gz.tmp" "${OUT}.gz")
  endif()
  get_filename_component(name "${OUT}" NAME)
  if(NOT IS_SYMLINK "${dir}/flexure-draw.1.gz")
    file(CREATE_LINK "${name}.gz" "${dir}/flexure-draw.1.gz" SYMBOLIC)
  endif()
endif()
