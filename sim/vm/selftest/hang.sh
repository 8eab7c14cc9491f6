# VM self-test script that never ends (runs inside the VM): the host's overall timeout must
# kill the VM and exit 124 however fast the machine boots it.
vm_log "hang: waiting for the host's overall timeout"
while :; do sleep 60; done
