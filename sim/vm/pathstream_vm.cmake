# The real-kernel test VM for CMake (docs/vm.md). Include it from any directory that registers
# VM tests:
#
#   include(${PROJECT_SOURCE_DIR}/sim/vm/pathstream_vm.cmake)
#   pathstream_add_vm_test(NAME hal.socketcan.vm
#     SCRIPT  ${CMAKE_CURRENT_SOURCE_DIR}/vm/socketcan.sh   # busybox sh, run inside the VM
#     PROGRAMS hal_socketcan_tests                          # targets or paths -> /pathstream/bin
#     DATA    ${CMAKE_CURRENT_SOURCE_DIR}/data/frames.csv   # files/dirs -> /pathstream/data
#     [GPIO_SIM] [NO_CAN] [TIMEOUT 60] [PROGRAM_TIMEOUT 20] [EXPECT_RC 0] [LABELS more labels])
#
# Every test gets the label "vm". Without the kernel cache of scripts/setup_vm.sh, with
# -DPATHSTREAM_VM_TESTS=OFF, or in a sanitizer build (PATHSTREAM_SANITIZE), the function
# registers nothing and the configure step says why, once. PATHSTREAM_VM_AVAILABLE tells
# callers whether VM tests are on.
include_guard(GLOBAL)

option(PATHSTREAM_VM_TESTS
  "Run the SocketCAN and gpio-sim tests in Debian's kernel under qemu (scripts/setup_vm.sh)" ON)

# Internal cache entries, not plain variables: the include guard is global, and a sibling
# directory that includes this file second must still see them.
set(PATHSTREAM_VM_RUNNER ${CMAKE_CURRENT_LIST_DIR}/run_in_vm.py CACHE INTERNAL "")
set(PATHSTREAM_VM_BASE_CACHE ${CMAKE_BINARY_DIR}/sim/vm/initramfs-cache CACHE INTERNAL "")

# The kernel that scripts/setup_vm.sh pins, and the cache it fills.
set(_vm_setup ${PROJECT_SOURCE_DIR}/scripts/setup_vm.sh)
set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${_vm_setup})
file(STRINGS ${_vm_setup} _vm_abi REGEX "^KERNEL_ABI=")
string(REGEX REPLACE "^KERNEL_ABI=([^ \t#]+).*" "\\1" _vm_abi "${_vm_abi}")
if(DEFINED ENV{PATHSTREAM_VM_CACHE})
  set(_vm_root $ENV{PATHSTREAM_VM_CACHE})
else()
  set(_vm_root /var/cache/pathstream-vm)
endif()
set(PATHSTREAM_VM_KERNEL_CACHE ${_vm_root}/${_vm_abi}-amd64 CACHE INTERNAL "")

set(_vm_on OFF)
find_program(PATHSTREAM_QEMU_X86 qemu-system-x86_64)
if(NOT PATHSTREAM_VM_TESTS)
  set(_vm_why "PATHSTREAM_VM_TESTS is OFF")
elseif(PATHSTREAM_SANITIZE OR PATHSTREAM_TSAN)
  set(_vm_why "sanitizer build (PATHSTREAM_SANITIZE or PATHSTREAM_TSAN): the VM tests run in the default build")
elseif(NOT EXISTS ${PATHSTREAM_VM_KERNEL_CACHE}/READY)
  set(_vm_why "no kernel cache at ${PATHSTREAM_VM_KERNEL_CACHE}: run scripts/setup_vm.sh "
              "(or scripts/setup.sh), then configure again")
elseif(NOT PATHSTREAM_QEMU_X86 OR NOT EXISTS /usr/bin/python3)
  set(_vm_why "qemu-system-x86_64 or /usr/bin/python3 missing: run scripts/setup.sh")
else()
  set(_vm_on ON)
  # A cache rebuilt by setup_vm.sh (another kernel) reconfigures.
  set_property(DIRECTORY ${PROJECT_SOURCE_DIR} APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${PATHSTREAM_VM_KERNEL_CACHE}/READY)
endif()
set(PATHSTREAM_VM_AVAILABLE ${_vm_on} CACHE INTERNAL "")
if(PATHSTREAM_VM_AVAILABLE)
  message(STATUS "VM tests: on (kernel ${_vm_abi}-amd64 from ${PATHSTREAM_VM_KERNEL_CACHE})")
else()
  string(JOIN "" _vm_why ${_vm_why})
  message(STATUS "VM tests: skipped: ${_vm_why}")
endif()

function(pathstream_add_vm_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "GPIO_SIM;NO_CAN"
    "NAME;SCRIPT;TIMEOUT;PROGRAM_TIMEOUT;EXPECT_RC" "PROGRAMS;DATA;LABELS")
  if(NOT arg_NAME OR NOT arg_SCRIPT)
    message(FATAL_ERROR "pathstream_add_vm_test: NAME and SCRIPT are required")
  endif()
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "pathstream_add_vm_test(${arg_NAME}): unknown ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT PATHSTREAM_VM_AVAILABLE)
    return()
  endif()
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 60)
  endif()
  if(NOT arg_PROGRAM_TIMEOUT)
    set(arg_PROGRAM_TIMEOUT 20)
  endif()
  get_filename_component(script ${arg_SCRIPT} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
  set(cmd /usr/bin/python3 ${PATHSTREAM_VM_RUNNER}
      --kernel-cache ${PATHSTREAM_VM_KERNEL_CACHE}
      --base-cache ${PATHSTREAM_VM_BASE_CACHE}
      --work ${CMAKE_CURRENT_BINARY_DIR}/vm-work/${arg_NAME}
      --script ${script}
      --timeout ${arg_TIMEOUT} --program-timeout ${arg_PROGRAM_TIMEOUT})
  foreach(p IN LISTS arg_PROGRAMS)
    if(TARGET ${p})
      list(APPEND cmd --program $<TARGET_FILE:${p}>)
    else()
      get_filename_component(p ${p} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
      list(APPEND cmd --program ${p})
    endif()
  endforeach()
  foreach(d IN LISTS arg_DATA)
    get_filename_component(d ${d} ABSOLUTE BASE_DIR ${CMAKE_CURRENT_SOURCE_DIR})
    list(APPEND cmd --data ${d})
  endforeach()
  if(arg_GPIO_SIM)
    list(APPEND cmd --gpio-sim)
  endif()
  if(arg_NO_CAN)
    list(APPEND cmd --no-can)
  endif()
  if(DEFINED arg_EXPECT_RC)
    list(APPEND cmd --expect-rc ${arg_EXPECT_RC})
  endif()
  add_test(NAME ${arg_NAME} COMMAND ${cmd})
  # ctest's own timeout is a backstop only: the harness kills the VM at TIMEOUT and says so.
  math(EXPR ctest_timeout "${arg_TIMEOUT} + 30")
  set(labels vm ${arg_LABELS})
  set_tests_properties(${arg_NAME} PROPERTIES LABELS "${labels}" TIMEOUT ${ctest_timeout})
endfunction()
