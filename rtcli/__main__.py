from rtcli.cli import main

main()
