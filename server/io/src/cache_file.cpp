// placeholder: being written (step 2)
