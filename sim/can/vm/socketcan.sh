# SocketCanBus on vcan0 (runs inside the VM): two sockets, filters, counters, timeouts.
vm_expect 0 socketcan_probe vcan0
