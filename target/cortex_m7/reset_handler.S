/* The vector table and the reset handler: what runs before any C or C++ code (docs/target.md,
 * "Start-up").
 *
 * In assembly because its first steps must come before the compiler could emit a floating-point
 * instruction (with -mfpu=fpv5-d16 GCC may copy or zero with VLDR/VSTR), and before anything uses the
 * stack it paints. The linker script (mps2_an500.ld) defines every symbol used here.
 */
    .syntax unified
    .cpu cortex-m7
    .fpu fpv5-d16
    .thumb

    .equ CPACR, 0xE000ED88          /* Coprocessor Access Control: CP10, CP11 = the FPU */
    .equ FPDSCR, 0xE000EF3C         /* the FPSCR value an exception handler's context starts with */
    .equ FPSCR_FZ, (1 << 24)        /* flush-to-zero (docs/floating-point.md) */
    .equ STACK_PAINT, 0x5A5AA5A5    /* stack_usage.hpp's kStackPaint */

    /* The vector table, at address 0 (the linker script's .vectors): the initial main stack pointer,
     * the reset handler, the system exceptions, then the NVIC's 32 external interrupts (QEMU's
     * num-irq for the board), none enabled yet. The handlers are in start_up.cpp and
     * instruction_clock.cpp; the linker sets each Thumb address's bit 0. */
    .section .vectors, "a", %progbits
    .global exc_vector_table
    .type exc_vector_table, %object
exc_vector_table:
    .word   __stack_top
    .word   exc_reset_handler
    .word   exc_fault_handler                   /* NMI */
    .word   exc_fault_handler                   /* HardFault */
    .word   exc_fault_handler                   /* MemManage */
    .word   exc_fault_handler                   /* BusFault */
    .word   exc_fault_handler                   /* UsageFault */
    .word   0, 0, 0, 0                          /* reserved */
    .word   exc_unexpected_interrupt_handler    /* SVCall */
    .word   exc_unexpected_interrupt_handler    /* DebugMonitor */
    .word   0                                   /* reserved */
    .word   exc_unexpected_interrupt_handler    /* PendSV */
    .word   exc_systick_handler                 /* SysTick */
    .rept   32
    .word   exc_unexpected_interrupt_handler
    .endr
    .size exc_vector_table, . - exc_vector_table

    .section .text.exc_reset_handler, "ax", %progbits
    .global exc_reset_handler
    .type exc_reset_handler, %function
    .thumb_func
exc_reset_handler:
    /* 1. The FPU: full access to CP10 and CP11; DSB so the write has completed and ISB so that no
     *    instruction after it was fetched under the old setting: the next may be a VFP instruction. */
    ldr     r0, =CPACR
    ldr     r1, [r0]
    orr     r1, r1, #(0xF << 20)
    str     r1, [r0]
    dsb
    isb
    /* Flush-to-zero in the main context and in every exception handler's, as the host's loop threads
     * run (a subnormal's cost must not depend on the run's history). */
    vmrs    r1, fpscr
    orr     r1, r1, #FPSCR_FZ
    vmsr    fpscr, r1
    ldr     r0, =FPDSCR
    ldr     r1, [r0]
    orr     r1, r1, #FPSCR_FZ
    str     r1, [r0]

    /* The main stack from the linker script (the vector table's word 0 says the same; a debugger
     * that jumps here may not have loaded it). */
    ldr     r0, =__stack_top
    mov     sp, r0

    /* 2. .data from its load address in flash to its run address in RAM (newlib's crt0 would not). */
    ldr     r0, =__data_load
    ldr     r1, =__data_start
    ldr     r2, =__data_end
1:  cmp     r1, r2
    bhs     2f
    ldr     r3, [r0], #4
    str     r3, [r1], #4
    b       1b

    /* 3. .bss zeroed. */
2:  ldr     r1, =__bss_start__
    ldr     r2, =__bss_end__
    movs    r3, #0
3:  cmp     r1, r2
    bhs     4f
    str     r3, [r1], #4
    b       3b

    /* 4. The whole stack painted (nothing is on it yet): the lowest word still painted later tells
     *    how deep it went. */
4:  ldr     r1, =__stack_limit
    ldr     r2, =__stack_top
    ldr     r3, =STACK_PAINT
5:  cmp     r1, r2
    bhs     6f
    str     r3, [r1], #4
    b       5b

    /* 5. The C and C++ run time (start_up.cpp): semihosting's stdio, the instruction clock, the
     *    command line, the static constructors; then main and exit with its status. */
6:  bl      exc_prepare_runtime
    ldr     r2, =exc_argc
    ldr     r0, [r2]
    ldr     r2, =exc_argv
    ldr     r1, [r2]
    bl      main
    bl      exit
7:  b       7b
    .pool
    .size exc_reset_handler, . - exc_reset_handler
