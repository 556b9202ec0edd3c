/* Thread entry (docs/isa.md): sp = top of the thread's local store, run the kernel, ebreak
 * ends the thread. */
    .file "start.S"
#include "dualsplit.h"

    .section .text.start, "ax"
    .globl _start
_start:
    li sp, LOCAL_STORE_ADDR + LOCAL_STORE_BYTES
    call kernel_main
    ebreak
