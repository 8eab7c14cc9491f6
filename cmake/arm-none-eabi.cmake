# CMake toolchain file: bare-metal Arm Cortex-M with Debian's gcc-arm-none-eabi.
#
# Usage: cmake -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake ...
# It sets only the compilers and binutils; the CPU (-mcpu=...) and the freestanding flags are
# chosen by the project that uses it (sim/cortex_m/target builds one tree per CPU).
# Optional: -DARM_NONE_EABI_ROOT=/opt/gcc-arm to use a toolchain outside PATH.

set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

set(_arm_hints "")
if(ARM_NONE_EABI_ROOT)
  list(APPEND _arm_hints "${ARM_NONE_EABI_ROOT}/bin")
endif()

find_program(ARM_NONE_EABI_GXX arm-none-eabi-g++ HINTS ${_arm_hints})
if(NOT ARM_NONE_EABI_GXX)
  message(FATAL_ERROR
    "arm-none-eabi-g++ not found: the Cortex-M build needs the Arm cross toolchain. "
    "Run scripts/setup.sh (installs gcc-arm-none-eabi, libstdc++-arm-none-eabi-newlib, "
    "qemu-system-arm), or configure with -DPATHSTREAM_CORTEX_M=OFF to skip it.")
endif()
get_filename_component(_arm_bin "${ARM_NONE_EABI_GXX}" DIRECTORY)

set(CMAKE_C_COMPILER   "${_arm_bin}/arm-none-eabi-gcc")
set(CMAKE_CXX_COMPILER "${ARM_NONE_EABI_GXX}")
set(CMAKE_ASM_COMPILER "${_arm_bin}/arm-none-eabi-gcc")
set(CMAKE_AR           "${_arm_bin}/arm-none-eabi-ar" CACHE FILEPATH "" FORCE)
set(CMAKE_RANLIB       "${_arm_bin}/arm-none-eabi-ranlib" CACHE FILEPATH "" FORCE)
set(CMAKE_OBJCOPY      "${_arm_bin}/arm-none-eabi-objcopy" CACHE FILEPATH "" FORCE)
set(CMAKE_OBJDUMP      "${_arm_bin}/arm-none-eabi-objdump" CACHE FILEPATH "" FORCE)
set(CMAKE_NM           "${_arm_bin}/arm-none-eabi-nm" CACHE FILEPATH "" FORCE)
set(CMAKE_SIZE         "${_arm_bin}/arm-none-eabi-size" CACHE FILEPATH "" FORCE)

# No OS, no startup files: compiler checks must not try to link an executable.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

# Never pick up host libraries or headers.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
