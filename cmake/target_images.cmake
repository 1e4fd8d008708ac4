# The emulated Cortex-M7's images (target/, docs/target.md), built for the test build, whose tests
# (tests/target) run them under QEMU. A separate CMake project with its own toolchain, so an external
# project of this one: configured and built with the outer build, through ccache when it compiles
# through ccache. Its tools are Debian packages; a test build without them stops here and names them.
#
# The firmware's image compiles the cycle's own libraries' sources (their SOURCES, so a source added
# to one of them is in the image too): included after those libraries are defined.
#
# Sets EXC_TARGET_SMOKE_IMAGE (the smoke image's ELF), EXC_TARGET_FIRMWARE_IMAGE (the firmware's),
# EXC_QEMU_SYSTEM_ARM, EXC_ARM_OBJDUMP, EXC_ARM_NM and EXC_ARM_SIZE for the tests and the harness.
# A missing tool stops the configuration, naming its Debian package.
include(ExternalProject)

find_program(EXC_TARGET_GXX arm-none-eabi-g++)
find_program(EXC_QEMU_SYSTEM_ARM qemu-system-arm)
set(_exc_target_missing "")
if(NOT EXC_TARGET_GXX OR NOT EXISTS "${EXC_TARGET_GXX}")
  list(APPEND _exc_target_missing "gcc-arm-none-eabi (arm-none-eabi-g++ not found: '${EXC_TARGET_GXX}')")
else()
  # The compiler alone is not enough: the C library, semihosting and C++ library of the Cortex-M7's
  # hard-float multilib each come in a package of their own.
  get_filename_component(_exc_target_bin ${EXC_TARGET_GXX} DIRECTORY)
  set(EXC_TARGET_GCC ${_exc_target_bin}/arm-none-eabi-gcc)
  foreach(_exc_pair "librdimon.a=libnewlib-arm-none-eabi" "libc.a=libnewlib-arm-none-eabi"
                    "libstdc++.a=libstdc++-arm-none-eabi-newlib")
    string(REPLACE "=" ";" _exc_pair "${_exc_pair}")
    list(GET _exc_pair 0 _exc_file)
    list(GET _exc_pair 1 _exc_package)
    execute_process(COMMAND ${EXC_TARGET_GXX} -mcpu=cortex-m7 -mfpu=fpv5-d16 -mfloat-abi=hard -mthumb
                            -print-file-name=${_exc_file}
                    OUTPUT_VARIABLE _exc_found OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
    if(NOT IS_ABSOLUTE "${_exc_found}" OR NOT EXISTS "${_exc_found}")
      list(APPEND _exc_target_missing "${_exc_package} (${_exc_file} for the Cortex-M7 hard-float multilib)")
    endif()
  endforeach()
  foreach(_exc_tool objdump nm size)
    string(TOUPPER ${_exc_tool} _exc_name)
    find_program(EXC_ARM_${_exc_name} arm-none-eabi-${_exc_tool} HINTS ${_exc_target_bin})
    if(NOT EXC_ARM_${_exc_name})
      list(APPEND _exc_target_missing "binutils-arm-none-eabi (arm-none-eabi-${_exc_tool})")
    endif()
  endforeach()
endif()
if(NOT EXC_QEMU_SYSTEM_ARM OR NOT EXISTS "${EXC_QEMU_SYSTEM_ARM}")
  list(APPEND _exc_target_missing "qemu-system-arm (qemu-system-arm not found: '${EXC_QEMU_SYSTEM_ARM}')")
endif()
if(_exc_target_missing)
  list(REMOVE_DUPLICATES _exc_target_missing)
  string(REPLACE ";" ", " _exc_target_missing "${_exc_target_missing}")
  message(FATAL_ERROR "The firmware's Cortex-M7 images (docs/target.md; EXC_TARGET_IMAGES, on in the test build, whose "
                      "tests run them under QEMU): this build misses the Debian packages: ${_exc_target_missing}. Install them with "
                      "'tools/install-deps test' (or apt-get install the packages named).")
endif()

# The cycle's sources, absolute, from the libraries that hold them.
set(_exc_firmware_sources "")
foreach(_exc_lib exc_settings_error exc_model exc_safety exc_control exc_settings_blob exc_firmware_cycle exc_hal_protocol)
  get_target_property(_exc_dir ${_exc_lib} SOURCE_DIR)
  get_target_property(_exc_sources ${_exc_lib} SOURCES)
  foreach(_exc_s ${_exc_sources})
    if(NOT IS_ABSOLUTE ${_exc_s})
      set(_exc_s ${_exc_dir}/${_exc_s})
    endif()
    list(APPEND _exc_firmware_sources ${_exc_s})
  endforeach()
endforeach()
string(REPLACE ";" "|" _exc_firmware_sources "${_exc_firmware_sources}")
# The generated message headers (lcmtypes/) and, alone in a folder of its own, LCM's portable
# lcm_coretypes.h that they include: the image sees no other host header.
find_file(EXC_LCM_CORETYPES lcm/lcm_coretypes.h REQUIRED)
set(_exc_lcm_core_dir ${CMAKE_BINARY_DIR}/target-include)
configure_file(${EXC_LCM_CORETYPES} ${_exc_lcm_core_dir}/lcm/lcm_coretypes.h COPYONLY)

get_target_property(_exc_eigen_includes Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
list(GET _exc_eigen_includes 0 _exc_eigen_include)
set(_exc_target_binary_dir ${CMAKE_BINARY_DIR}/target-cortex-m7)
set(EXC_TARGET_SMOKE_IMAGE ${_exc_target_binary_dir}/cortex_m7/cortex_m7_smoke.elf)
set(EXC_TARGET_FIRMWARE_IMAGE ${_exc_target_binary_dir}/cortex_m7/cortex_m7_firmware.elf)
ExternalProject_Add(exc_target_images
  SOURCE_DIR ${EXC_SOURCE_DIR}/target
  BINARY_DIR ${_exc_target_binary_dir}
  CMAKE_ARGS -DCMAKE_TOOLCHAIN_FILE=${EXC_SOURCE_DIR}/cmake/toolchain-cortex-m7.cmake
  CMAKE_CACHE_ARGS
    -DEXC_ARM_GCC:FILEPATH=${EXC_TARGET_GCC}
    -DEXC_ARM_GXX:FILEPATH=${EXC_TARGET_GXX}
    -DEXC_EIGEN3_INCLUDE_DIR:PATH=${_exc_eigen_include}
    -DEXC_FIRMWARE_SOURCES:STRING=${_exc_firmware_sources}
    -DEXC_LCM_INCLUDE_DIRS:STRING=${CMAKE_BINARY_DIR}/lcmtypes|${_exc_lcm_core_dir}
    -DCMAKE_C_COMPILER_LAUNCHER:STRING=${CMAKE_C_COMPILER_LAUNCHER}
    -DCMAKE_CXX_COMPILER_LAUNCHER:STRING=${CMAKE_CXX_COMPILER_LAUNCHER}
  # The inner build decides what changed (a few seconds when nothing did).
  BUILD_ALWAYS ON
  INSTALL_COMMAND ""
  LIST_SEPARATOR |
  DEPENDS exc_lcmtypes_generate
  BUILD_BYPRODUCTS ${EXC_TARGET_SMOKE_IMAGE} ${EXC_TARGET_FIRMWARE_IMAGE})
