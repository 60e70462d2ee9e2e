add_library(drift_warnings INTERFACE)
target_compile_options(drift_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:C>:-Wall -Wextra -Wpedantic -Wshadow -Wstrict-prototypes
  -Wmissing-prototypes -Wold-style-definition -Wvla -Wformat=2 -Wundef
  -Wdouble-promotion -Wimplicit-fallthrough -Werror=implicit-function-declaration
  -Werror=return-type -ffp-contract=off>
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wformat=2 -Wdouble-promotion
  -ffp-contract=off>)
if(DRIFT_WERROR)
  target_compile_options(drift_warnings INTERFACE $<$<COMPILE_LANGUAGE:C,CXX>:-Werror>)
endif()
