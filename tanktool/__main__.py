from tanktool.cli.main import main

main()
