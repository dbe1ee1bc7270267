# Renders a man page for the package: @VERSION@ replaced by VERSION; if
# EXAMPLE is given, @EXAMPLE@ by that file's text as literal lines (so that
# dnbridge.toml(5) shows the annotated example itself, never a copy that can
# drift from it); if KEYS is given, @KEYS@ by that file's roff (the key
# reference config_keys_roff writes from the key table). Writes OUTPUT and
# OUTPUT.gz (gzip -9n: no name or time in it, the same bytes from the same
# text).
#   cmake -DINPUT=page.5 -DOUTPUT=out/page.5 -DVERSION=0.1.0 [-DEXAMPLE=file] [-DKEYS=file]
#         -P render.cmake
cmake_minimum_required(VERSION 3.25)
file(READ ${INPUT} text)
string(REPLACE "@VERSION@" "${VERSION}" text "${text}")
if(EXAMPLE)
  file(READ ${EXAMPLE} example)
  string(STRIP "${example}" example)
  # Literal text in roff: a backslash is \e, a minus is \- (not a hyphen,
  # so that keys and values copy as typed), and \& at the start of every
  # line keeps a leading . or ' from being read as a request.
  string(REPLACE "\\" "\\e" example "${example}")
  string(REPLACE "-" "\\-" example "${example}")
  string(REPLACE "\n" "\n\\&" example "\\&${example}")
  string(REPLACE "@EXAMPLE@" "${example}" text "${text}")
endif()
if(KEYS)
  file(READ ${KEYS} keys)
  string(STRIP "${keys}" keys)
  string(REPLACE "@KEYS@" "${keys}" text "${text}")
endif()
file(WRITE ${OUTPUT} "${text}")
execute_process(COMMAND gzip -9nfk ${OUTPUT} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "gzip ${OUTPUT} failed")
endif()
