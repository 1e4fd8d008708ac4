# Bare-metal Cortex-M7 with the double-precision FPU (FPv5-D16), hard-float ABI: Debian 12's
# arm-none-eabi GCC 12.2 (gcc-arm-none-eabi) with full newlib (libnewlib-arm-none-eabi, not nano, so
# printf prints doubles) and libstdc++ (libstdc++-arm-none-eabi-newlib). Semihosting through
# rdimon.specs: stdio, files and exit go to the debugger or, here, to QEMU (docs/target.md).
#
#   cmake -S target -B build-target -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-cortex-m7.cmake
set(CMAKE_SYSTEM_NAME Generic)
set(CMAKE_SYSTEM_PROCESSOR arm)

find_program(EXC_ARM_GCC arm-none-eabi-gcc)
find_program(EXC_ARM_GXX arm-none-eabi-g++)
if(NOT EXC_ARM_GCC OR NOT EXC_ARM_GXX)
  message(FATAL_ERROR "arm-none-eabi-gcc/g++ not found: install the Debian packages gcc-arm-none-eabi, "
                      "libnewlib-arm-none-eabi and libstdc++-arm-none-eabi-newlib (tools/install-deps test)")
endif()
set(CMAKE_C_COMPILER ${EXC_ARM_GCC})
set(CMAKE_CXX_COMPILER ${EXC_ARM_GXX})
set(CMAKE_ASM_COMPILER ${EXC_ARM_GCC})
# try_compile links no executable: without the start-up code and linker script a link would fail.
set(CMAKE_TRY_COMPILE_TARGET_TYPE STATIC_LIBRARY)

set(_exc_cpu_flags "-mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb")
# Every function and object in its own section, so --gc-sections drops what the image never calls.
set(CMAKE_C_FLAGS_INIT "${_exc_cpu_flags} -ffunction-sections -fdata-sections")
set(CMAKE_CXX_FLAGS_INIT "${_exc_cpu_flags} -ffunction-sections -fdata-sections")
set(CMAKE_ASM_FLAGS_INIT "${_exc_cpu_flags}")
# rdimon.specs: newlib's semihosting system calls (librdimon). The linker script and the start-up
# code are the image's own (target/cortex_m7), added by the project that links it.
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_exc_cpu_flags} -specs=rdimon.specs -Wl,--gc-sections")

set(CMAKE_CXX_STANDARD 17)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)

# Headers and libraries of the target only; programs (code generators) from the host.
set(CMAKE_FIND_ROOT_PATH /usr/lib/arm-none-eabi)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
